//! Closest-point projection of a point onto a master facet of any contact
//! type (tri3, quad4, tri6, quad8, quad9).
//!
//! The facet is the fem module's isoparametric surface `x²(ξ) = Σ N_b(ξ) x_b`
//! (node order and reference coordinates of [`FacetType`]), extended beyond
//! the reference facet by the same polynomial so a point just past an edge
//! still gets a smooth projection (the contact search decides from
//! [`Projection::outside`] whether to keep it).
//!
//! The projection minimises `φ(ξ) = ½ |x − x²(ξ)|²`. Its stationarity
//! conditions are `F_α = (x − x²)·τ_α = 0` with `τ_α = ∂x²/∂ξ_α`, and its
//! Hessian is `H_αβ = τ_α·τ_β − (x − x²)·∂τ_α/∂ξ_β`, with every second
//! derivative of the shape functions (only the mixed one of the bilinear
//! quad on a first-order facet, all three on a curved second-order one).
//! Newton with the full Hessian converges quadratically also on warped and
//! curved facets, where the second term is non-zero. Second-order facets
//! share the reference facet of their first-order counterpart (tri6 the
//! triangle, quad8 and quad9 the square), so `outside` and the search box
//! are the same. Safeguards so it never diverges: when `H` is not
//! positive definite the metric `τ_α·τ_β` (Gauss–Newton) or the gradient is
//! used instead, steps are limited in length, large steps must decrease `φ`
//! (backtracking), and `ξ` is kept in a box around the reference facet. A
//! minimiser that would lie outside that box ends as a clamped answer with
//! `converged = false`.

use crate::contact::{facet_second, facet_shape, LINEAR_FACET_NODES, MAX_FACET_NODES};
use crate::fem::FacetType;
use crate::vec3::{add, cross, dot, norm, sub};

/// Result of [`project`].
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Projection {
    /// Facet coordinates of the closest point (possibly outside the
    /// reference facet, see `outside`).
    pub xi: [f64; 2],
    /// The closest point `x²(ξ)`.
    pub point: [f64; 3],
    /// Unit outward normal `τ₁×τ₂/|τ₁×τ₂|` at `xi`; all zeros when the facet
    /// has no normal there (degenerate facet).
    pub normal: [f64; 3],
    /// `(x − point)·normal`: `> 0` apart, `< 0` penetration.
    /// `f64::INFINITY` when the projection is unusable (bad input or no
    /// normal), so a caller that ignores `converged` still sees no contact.
    pub gap: f64,
    /// Newton met its tolerance at an unconstrained stationary point.
    pub converged: bool,
    /// How far `xi` lies outside the reference facet, in reference units: the
    /// largest violation of its inequalities (quad `|ξ_α| ≤ 1`; tri
    /// `ξ₁ ≥ 0, ξ₂ ≥ 0, ξ₁ + ξ₂ ≤ 1`); 0 inside. `f64::INFINITY` on bad input.
    pub outside: f64,
}

/// Relative Newton tolerance on the step in reference coordinates.
const TOL: f64 = 1e-13;
/// Longest step in reference units: the facet spans 1–2 units, so a longer
/// step only jumps over the local geometry.
const MAX_STEP: f64 = 0.5;
/// Steps shorter than this are taken without the decrease test, because
/// near the solution `φ` changes by less than its round-off and a decrease
/// test would reject the steps that give quadratic convergence.
const SMALL_STEP: f64 = 1e-4;
const MAX_ITER: usize = 60;
const MAX_HALVINGS: usize = 40;
/// Relative threshold below which a 2×2 matrix counts as singular.
const SINGULAR: f64 = 1e-12;

/// Closest-point projection of `x` onto the facet through `master` (current
/// nodal positions, fem node order), started from `start` (typically the
/// last `ξ̄`) or the facet centre. Never panics and never returns NaN: bad
/// input gives `converged = false`, `gap = ∞`.
pub fn project(
    facet: FacetType,
    master: &[[f64; 3]],
    x: [f64; 3],
    start: Option<[f64; 2]>,
) -> Projection {
    project_counted(facet, master, x, start).0
}

/// Reference coordinates of the facet centre (the default Newton start).
pub fn reference_centre(facet: FacetType) -> [f64; 2] {
    match facet.linear() {
        FacetType::Tri3 => [1.0 / 3.0, 1.0 / 3.0],
        _ => [0.0, 0.0],
    }
}

/// Largest violation of the reference facet's inequalities at `xi`.
pub fn outside_distance(facet: FacetType, xi: [f64; 2]) -> f64 {
    let violation = match facet.linear() {
        FacetType::Tri3 => (-xi[0]).max(-xi[1]).max(xi[0] + xi[1] - 1.0),
        _ => (xi[0].abs() - 1.0).max(xi[1].abs() - 1.0),
    };
    violation.max(0.0)
}

/// Box that keeps `ξ` near the reference facet: one facet width beyond each
/// edge (quad `[-2, 2]²`, tri `[-1, 2]²`). A projection further out belongs
/// to another facet, and the bilinear extension may fold there.
fn search_box(facet: FacetType) -> (f64, f64) {
    match facet.linear() {
        FacetType::Tri3 => (-1.0, 2.0),
        _ => (-2.0, 2.0),
    }
}

/// The facet translated so its node centroid is the origin. Working relative
/// to the centroid keeps round-off proportional to the facet size rather
/// than to the distance from the global origin. `M`: the node capacity
/// (four for first-order facets, so they carry no second-order slack).
struct Frame<const M: usize> {
    facet: FacetType,
    nodes: [[f64; 3]; M],
    centre: [f64; 3],
    /// Largest node distance from the centroid: the length scale.
    size: f64,
    /// A second-order facet: `τ_11` and `τ_22` are not zero.
    curved: bool,
}

impl<const M: usize> Frame<M> {
    fn new(facet: FacetType, master: &[[f64; 3]]) -> Option<Self> {
        let n = facet.nodes();
        if n > M || master.len() != n || !master.iter().flatten().all(|v| v.is_finite()) {
            return None;
        }
        let mut centre = [0.0; 3];
        for p in master {
            centre = add(centre, p.map(|c| c / n as f64));
        }
        let mut nodes = [[0.0; 3]; M];
        let mut size = 0.0f64;
        for (local, p) in nodes.iter_mut().zip(master) {
            *local = sub(*p, centre);
            size = size.max(norm(*local));
        }
        if !(size > 0.0 && size.is_finite()) {
            return None;
        }
        Some(Frame {
            facet,
            nodes,
            centre,
            size,
            curved: !facet.is_linear(),
        })
    }

    fn count(&self) -> usize {
        self.facet.nodes()
    }

    fn surface(&self, xi: [f64; 2]) -> Surface {
        let s = facet_shape::<M>(self.facet, xi);
        let dd = facet_second::<M>(self.facet, xi);
        let mut out = Surface {
            curved: self.curved,
            ..Surface::default()
        };
        let nodes = self.nodes.iter().zip(&s.n).zip(&s.dn).zip(&dd);
        for (((xb, n), dn), ddb) in nodes.take(self.count()) {
            out.x = add(out.x, xb.map(|c| n * c));
            out.t1 = add(out.t1, xb.map(|c| dn[0] * c));
            out.t2 = add(out.t2, xb.map(|c| dn[1] * c));
            out.t12 = add(out.t12, xb.map(|c| ddb[1] * c));
            if self.curved {
                out.t11 = add(out.t11, xb.map(|c| ddb[0] * c));
                out.t22 = add(out.t22, xb.map(|c| ddb[2] * c));
            }
        }
        out
    }
}

/// Position, tangents and second derivatives of the surface at one `ξ`
/// (centroid-relative); `t11 = t22 = 0` on first-order facets.
#[derive(Default)]
struct Surface {
    x: [f64; 3],
    t1: [f64; 3],
    t2: [f64; 3],
    t12: [f64; 3],
    t11: [f64; 3],
    t22: [f64; 3],
    curved: bool,
}

impl Surface {
    /// `τ_α·τ_β`.
    fn metric(&self) -> Sym2 {
        Sym2 {
            a: dot(self.t1, self.t1),
            b: dot(self.t1, self.t2),
            c: dot(self.t2, self.t2),
        }
    }

    /// Hessian of `φ` with `d = x − x²`; on a first-order facet
    /// `∂τ₁/∂ξ₁ = ∂τ₂/∂ξ₂ = 0`, so only the off-diagonal gets a curvature
    /// term.
    fn hessian(&self, d: [f64; 3]) -> Sym2 {
        let m = self.metric();
        if self.curved {
            Sym2 {
                a: m.a - dot(d, self.t11),
                b: m.b - dot(d, self.t12),
                c: m.c - dot(d, self.t22),
            }
        } else {
            Sym2 {
                b: m.b - dot(d, self.t12),
                ..m
            }
        }
    }
}

/// Symmetric 2×2 matrix `[[a, b], [b, c]]`.
#[derive(Clone, Copy)]
struct Sym2 {
    a: f64,
    b: f64,
    c: f64,
}

impl Sym2 {
    fn positive_definite(&self) -> bool {
        let det = self.a * self.c - self.b * self.b;
        self.a > 0.0 && self.c > 0.0 && det > SINGULAR * self.a * self.c
    }

    /// Solve restricted to the free components (the others stay zero), or
    /// `None` if the restricted matrix is not positive definite.
    fn solve_free(&self, f: [f64; 2], free: [bool; 2]) -> Option<[f64; 2]> {
        match free {
            [true, true] => {
                if !self.positive_definite() {
                    return None;
                }
                let det = self.a * self.c - self.b * self.b;
                Some([
                    (self.c * f[0] - self.b * f[1]) / det,
                    (self.a * f[1] - self.b * f[0]) / det,
                ])
            }
            [true, false] => (self.a > 0.0).then(|| [f[0] / self.a, 0.0]),
            [false, true] => (self.c > 0.0).then(|| [0.0, f[1] / self.c]),
            [false, false] => None,
        }
    }
}

/// Descent direction for `φ` at one iterate: Newton with the full Hessian if
/// that is positive definite, else Gauss–Newton with the metric, else a
/// scaled gradient step. `f = −∇φ`.
fn direction(s: &Surface, d: [f64; 3], f: [f64; 2], free: [bool; 2]) -> Option<[f64; 2]> {
    let metric = s.metric();
    let hessian = s.hessian(d);
    let gradient = || {
        let scale = metric.a + metric.c;
        (scale > 0.0).then(|| {
            let keep = free.map(|fr| if fr { 1.0 } else { 0.0 });
            [keep[0] * f[0] / scale, keep[1] * f[1] / scale]
        })
    };
    let dir = hessian
        .solve_free(f, free)
        .or_else(|| metric.solve_free(f, free))
        .or_else(gradient)?;
    dir.iter().all(|v| v.is_finite()).then_some(dir)
}

fn clamp_box(xi: [f64; 2], (lo, hi): (f64, f64)) -> [f64; 2] {
    xi.map(|v| v.clamp(lo, hi))
}

/// Components pinned at the search box: at a bound with the descent
/// direction `f` pointing out of the box.
fn free_components(xi: [f64; 2], f: [f64; 2], (lo, hi): (f64, f64)) -> [bool; 2] {
    [0, 1].map(|i| !((xi[i] <= lo && f[i] < 0.0) || (xi[i] >= hi && f[i] > 0.0)))
}

fn objective<const M: usize>(frame: &Frame<M>, y: [f64; 3], xi: [f64; 2]) -> f64 {
    let d = sub(y, frame.surface(xi).x);
    0.5 * dot(d, d)
}

/// Shortens `dir` to at most `MAX_STEP` in the max norm.
fn limit_step(dir: [f64; 2]) -> [f64; 2] {
    let len = dir[0].abs().max(dir[1].abs());
    if len > MAX_STEP {
        dir.map(|v| v * MAX_STEP / len)
    } else {
        dir
    }
}

/// Backtracking along `dir` (projected onto the box) until `φ` decreases.
fn line_search<const M: usize>(
    frame: &Frame<M>,
    y: [f64; 3],
    xi: [f64; 2],
    dir: [f64; 2],
) -> Option<[f64; 2]> {
    let bounds = search_box(frame.facet);
    let phi = objective(frame, y, xi);
    let mut alpha = 1.0;
    for _ in 0..MAX_HALVINGS {
        let trial = clamp_box([xi[0] + alpha * dir[0], xi[1] + alpha * dir[1]], bounds);
        if trial == xi {
            return None;
        }
        if objective(frame, y, trial) < phi {
            return Some(trial);
        }
        alpha *= 0.5;
    }
    None
}

/// Starting point: `start` if usable, else the facet centre; inside the box.
fn initial_xi(facet: FacetType, start: Option<[f64; 2]>) -> [f64; 2] {
    match start {
        Some(s) if s.iter().all(|v| v.is_finite()) => clamp_box(s, search_box(facet)),
        _ => reference_centre(facet),
    }
}

/// Newton iteration; returns the final `ξ`, whether it converged, and the
/// number of iterations (for tests of the convergence rate).
fn newton<const M: usize>(
    frame: &Frame<M>,
    y: [f64; 3],
    mut xi: [f64; 2],
) -> ([f64; 2], bool, usize) {
    let bounds = search_box(frame.facet);
    // Round-off in F grows with the distance of x from the facet, so the
    // attainable accuracy of ξ does too.
    let tol = TOL * (1.0 + norm(y) / frame.size);
    for it in 0..MAX_ITER {
        let s = frame.surface(xi);
        let d = sub(y, s.x);
        let f = [dot(d, s.t1), dot(d, s.t2)];
        let free = free_components(xi, f, bounds);
        let Some(dir) = direction(&s, d, f, free) else {
            return (xi, false, it);
        };
        let len = dir[0].abs().max(dir[1].abs());
        let constrained = free != [true, true];
        if len <= tol {
            let next = clamp_box([xi[0] + dir[0], xi[1] + dir[1]], bounds);
            let converged = !constrained && next == [xi[0] + dir[0], xi[1] + dir[1]];
            return (next, converged, it + 1);
        }
        let next = if len <= SMALL_STEP {
            Some(clamp_box([xi[0] + dir[0], xi[1] + dir[1]], bounds))
        } else {
            line_search(frame, y, xi, limit_step(dir))
        };
        match next {
            Some(n) if n != xi => xi = n,
            // No progress possible: a clamped minimiser on the box boundary
            // or a degenerate neighbourhood.
            _ => return (xi, false, it + 1),
        }
    }
    (xi, false, MAX_ITER)
}

fn failed(xi: [f64; 2]) -> Projection {
    Projection {
        xi,
        point: [0.0; 3],
        normal: [0.0; 3],
        gap: f64::INFINITY,
        converged: false,
        outside: f64::INFINITY,
    }
}

/// [`project`] plus the Newton iteration count.
pub(crate) fn project_counted(
    facet: FacetType,
    master: &[[f64; 3]],
    x: [f64; 3],
    start: Option<[f64; 2]>,
) -> (Projection, usize) {
    if facet.is_linear() {
        project_in::<LINEAR_FACET_NODES>(facet, master, x, start)
    } else {
        project_in::<MAX_FACET_NODES>(facet, master, x, start)
    }
}

/// [`project_counted`] in holders of `M` nodes.
fn project_in<const M: usize>(
    facet: FacetType,
    master: &[[f64; 3]],
    x: [f64; 3],
    start: Option<[f64; 2]>,
) -> (Projection, usize) {
    let xi0 = initial_xi(facet, start);
    let Some(frame) = Frame::<M>::new(facet, master) else {
        return (failed(xi0), 0);
    };
    if !x.iter().all(|v| v.is_finite()) {
        return (failed(xi0), 0);
    }
    let y = sub(x, frame.centre);
    let (xi, converged, iterations) = newton(&frame, y, xi0);
    (finish(&frame, y, xi, converged), iterations)
}

/// Point, normal and gap at the final `ξ`.
fn finish<const M: usize>(
    frame: &Frame<M>,
    y: [f64; 3],
    xi: [f64; 2],
    converged: bool,
) -> Projection {
    let s = frame.surface(xi);
    let n = cross(s.t1, s.t2);
    let area = norm(n);
    let point = add(s.x, frame.centre);
    let outside = outside_distance(frame.facet, xi);
    // A facet collapsed at ξ has no normal, so no gap: report "no contact".
    if !(area > SINGULAR * norm(s.t1) * norm(s.t2) && area > 0.0) {
        return Projection {
            xi,
            point,
            normal: [0.0; 3],
            gap: f64::INFINITY,
            converged: false,
            outside,
        };
    }
    let normal = n.map(|v| v / area);
    let d = sub(y, s.x);
    // A stationary point that is not a local minimum (reachable through the
    // Gauss–Newton fallback) is not a closest point, and the link tangent
    // needs an invertible Hessian there.
    let minimum = s.hessian(d).positive_definite();
    Projection {
        xi,
        point,
        normal,
        gap: dot(d, normal),
        converged: converged && minimum,
        outside,
    }
}

#[cfg(test)]
mod curved_tests;
#[cfg(test)]
mod tests;
