//! Tests of the link kernel: finite-difference checks of the residual
//! (gradient of the potential) and of the exact tangent, symmetry, balance
//! and invariance, closed forms, bad input. This file holds the random test
//! cases; `normal.rs` the frictionless tests, `friction.rs` the Coulomb ones.

mod curved;
mod friction;
mod normal;

use super::*;
use crate::contact::{autodiff, projection};
use crate::fem::test_util::{rel_err, Lcg};
use crate::fem::{FacetType, QuadRule};

/// Owned counterpart of [`LinkMaster`], so test cases can be perturbed.
#[derive(Clone)]
enum OwnedMaster {
    Facet(FacetType, Vec<[f64; 3]>),
    Rigid(LinkMaster<'static>),
}

#[derive(Clone)]
struct Case {
    slave_facet: FacetType,
    slave_x: Vec<[f64; 3]>,
    zeta: [f64; 2],
    weight: f64,
    master: OwnedMaster,
    lambda_n: f64,
    penalty: f64,
    friction: Option<CaseFriction>,
}

/// (slave v, master v, Δt, dv/dx).
type CaseRate = (Vec<[f64; 3]>, Vec<[f64; 3]>, f64, f64);

/// Owned counterpart of [`Friction`].
#[derive(Clone)]
struct CaseFriction {
    mu: f64,
    penalty: f64,
    history: SlipHistory,
    rate: Option<CaseRate>,
}

impl Case {
    fn input(&self) -> LinkInput<'_> {
        let master = match &self.master {
            OwnedMaster::Facet(facet, x) => LinkMaster::Facet { facet: *facet, x },
            OwnedMaster::Rigid(m) => *m,
        };
        let xi_start = match &self.master {
            OwnedMaster::Facet(f, _) => projection::reference_centre(*f),
            OwnedMaster::Rigid(_) => [0.0; 2],
        };
        LinkInput {
            slave_facet: self.slave_facet,
            slave_x: &self.slave_x,
            zeta: self.zeta,
            weight: self.weight,
            master,
            xi_start,
            lambda_n: self.lambda_n,
            penalty: self.penalty,
            friction: self.friction.as_ref().map(|f| Friction {
                mu: f.mu,
                penalty: f.penalty,
                history: f.history,
                rate: f.rate.as_ref().map(|(vs, vm, dt, c)| SlipRate {
                    slave_v: vs,
                    master_v: vm,
                    dt: *dt,
                    dv_dx: *c,
                }),
            }),
            main_part_tangent: false,
        }
    }

    fn n(&self) -> usize {
        dof_count(&self.input())
    }

    /// All nodal positions in DOF order (slave, then master).
    fn nodes(&self) -> Vec<[f64; 3]> {
        let mut v = self.slave_x.clone();
        if let OwnedMaster::Facet(_, x) = &self.master {
            v.extend_from_slice(x);
        }
        v
    }

    fn shifted(&self, dof: usize, h: f64) -> Case {
        let mut c = self.clone();
        let (node, i) = (dof / 3, dof % 3);
        let ns = c.slave_x.len();
        if node < ns {
            c.slave_x[node][i] += h;
        } else if let OwnedMaster::Facet(_, x) = &mut c.master {
            x[node - ns][i] += h;
        }
        // The integrator's velocity moves with the position.
        if let Some((vs, vm, _, dv_dx)) = c.friction.as_mut().and_then(|f| f.rate.as_mut()) {
            if node < ns {
                vs[node][i] += *dv_dx * h;
            } else if let Some(v) = vm.get_mut(node - ns) {
                if matches!(self.master, OwnedMaster::Facet(..)) {
                    v[i] += *dv_dx * h;
                }
            }
        }
        c
    }

    fn translated(&self, t: [f64; 3]) -> Case {
        let mut c = self.clone();
        let shift = |p: &mut [f64; 3]| *p = autodiff::add(p, &t);
        c.slave_x.iter_mut().for_each(shift);
        if let OwnedMaster::Facet(_, x) = &mut c.master {
            x.iter_mut().for_each(shift);
        }
        c
    }

    fn residual(&self) -> Vec<f64> {
        let mut r = vec![0.0; self.n()];
        residual_tangent(&self.input(), &mut r, None);
        r
    }

    fn residual_and_tangent(&self) -> (Vec<f64>, Vec<f64>, LinkState) {
        let n = self.n();
        let (mut r, mut k) = (vec![0.0; n], vec![0.0; n * n]);
        let state = residual_tangent(&self.input(), &mut r, Some(&mut k));
        (r, k, state)
    }
}

const H: f64 = 1e-6;

fn fd_gradient_of_potential(c: &Case) -> Vec<f64> {
    (0..c.n())
        .map(|j| {
            let p = potential(&c.shifted(j, H).input());
            let m = potential(&c.shifted(j, -H).input());
            (p - m) / (2.0 * H)
        })
        .collect()
}

/// Row-major n×n with column j = central difference of r along DOF j.
fn fd_tangent(c: &Case) -> Vec<f64> {
    let n = c.n();
    let mut k = vec![0.0; n * n];
    for j in 0..n {
        let (p, m) = (c.shifted(j, H).residual(), c.shifted(j, -H).residual());
        for i in 0..n {
            k[i * n + j] = (p[i] - m[i]) / (2.0 * H);
        }
    }
    k
}

fn asymmetry(k: &[f64], n: usize) -> f64 {
    let scale = k.iter().fold(0.0f64, |m, v| m.max(v.abs()));
    let mut worst = 0.0f64;
    for i in 0..n {
        for j in 0..n {
            worst = worst.max((k[i * n + j] - k[j * n + i]).abs());
        }
    }
    worst / scale
}

fn random_zeta(facet: FacetType, rng: &mut Lcg) -> [f64; 2] {
    match facet.linear() {
        FacetType::Quad4 => [0.9 * rng.next(), 0.9 * rng.next()],
        _ => {
            let (a, b) = (0.5 * (rng.next() + 1.0), 0.5 * (rng.next() + 1.0));
            if a + b < 1.0 {
                [a, b]
            } else {
                [1.0 - a, 1.0 - b]
            }
        }
    }
}

fn perturbed(base: &[[f64; 2]], z: f64, amp: f64, rng: &mut Lcg) -> Vec<[f64; 3]> {
    base.iter()
        .map(|p| autodiff::add(&[p[0], p[1], z], &rng.vec3(amp)))
        .collect()
}

/// Slave facet around z = z0, oriented with its outward normal −z (its
/// body is above), arbitrarily deformed.
fn slave_nodes(facet: FacetType, z0: f64, rng: &mut Lcg) -> Vec<[f64; 3]> {
    let base: &[[f64; 2]] = match facet.linear() {
        FacetType::Quad4 => &[[-0.4, -0.4], [-0.4, 0.4], [0.4, 0.4], [0.4, -0.4]],
        _ => &[[-0.4, -0.4], [-0.2, 0.4], [0.4, -0.1]],
    };
    perturbed(base, z0, 0.08, rng)
}

/// Warped master facet around z = 0, outward normal +z.
fn master_nodes(facet: FacetType, rng: &mut Lcg) -> Vec<[f64; 3]> {
    let base: &[[f64; 2]] = match facet.linear() {
        FacetType::Quad4 => &[[-1.0, -1.0], [1.0, -1.0], [1.0, 1.0], [-1.0, 1.0]],
        _ => &[[-1.0, -1.0], [1.6, -0.8], [-0.6, 1.6]],
    };
    let mut x = perturbed(base, 0.0, 0.1, rng);
    for p in &mut x {
        p[2] += 0.1 * rng.next();
    }
    x
}

fn rigid_masters() -> [LinkMaster<'static>; 3] {
    [
        LinkMaster::Plane {
            point: [0.05, -0.02, 0.01],
            normal: [0.1, -0.15, 2.0],
        },
        LinkMaster::Sphere {
            centre: [0.1, 0.05, -1.3],
            radius: 1.3,
        },
        LinkMaster::Cylinder {
            point: [0.0, 0.0, -1.3],
            axis: [1.0, 0.2, 0.1],
            radius: 1.3,
        },
    ]
}

/// A random closed link (pN ≥ 0.05, away from the kink at pN = 0): the
/// slave point penetrates or lies slightly apart with λN large enough.
fn random_case(slave: FacetType, master: Option<FacetType>, rigid: usize, rng: &mut Lcg) -> Case {
    loop {
        let master = match master {
            Some(f) => OwnedMaster::Facet(f, master_nodes(f, rng)),
            None => OwnedMaster::Rigid(rigid_masters()[rigid]),
        };
        let case = Case {
            slave_facet: slave,
            slave_x: slave_nodes(slave, 0.05 * rng.next() - 0.03, rng),
            zeta: random_zeta(slave, rng),
            weight: 0.3 + 0.2 * rng.next(),
            master,
            lambda_n: 0.5 * (rng.next() + 1.0),
            penalty: 20.0,
            friction: None,
        };
        let s = evaluate(&case.input());
        if s.projection_converged && s.pressure > 0.05 && s.outside < 0.5 {
            return case;
        }
    }
}

/// Every facet pairing and every rigid master, a few random cases each.
fn all_cases() -> Vec<(String, Case)> {
    let mut rng = Lcg::new(42);
    let facets = [FacetType::Quad4, FacetType::Tri3];
    let mut out = Vec::new();
    for _ in 0..4 {
        for s in facets {
            for m in facets {
                let name = format!("{}-{}", s.name(), m.name());
                out.push((name, random_case(s, Some(m), 0, &mut rng)));
            }
            for (i, kind) in ["plane", "sphere", "cylinder"].iter().enumerate() {
                let name = format!("{}-{kind}", s.name());
                out.push((name, random_case(s, None, i, &mut rng)));
            }
        }
    }
    out
}

/// Runs `measure` on every case, asserts `< limit`, and prints the
/// worst value per pairing (run with --nocapture to see them).
fn check_all(what: &str, limit: f64, measure: impl Fn(&Case) -> f64) {
    let mut worst = std::collections::BTreeMap::<String, f64>::new();
    for (name, case) in all_cases() {
        let err = measure(&case);
        assert!(err < limit, "{name}: {what} = {err:e}");
        let w = worst.entry(name).or_insert(0.0);
        *w = w.max(err);
    }
    for (name, err) in worst {
        println!("{what:>22} {name:>15}: {err:.1e}");
    }
}
