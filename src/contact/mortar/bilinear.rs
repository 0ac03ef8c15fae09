//! A facet's map from parametric coordinates onto the auxiliary plane in
//! f64, and its inversion by Newton (the mortar's segment points are mapped
//! back to both facets through it; `geometry::PlanarMap` adds the
//! derivative in `T`).
use crate::contact::autodiff::Scalar;
use crate::fem::FacetType;

type Vec2 = [f64; 2];

fn sub(a: Vec2, b: Vec2) -> Vec2 {
    [a[0] - b[0], a[1] - b[1]]
}

/// A facet's planar map in f64 as `x(ζ) = c + a₁ ζ₁ + a₂ ζ₂ + b ζ₁ ζ₂`
/// (`b = 0` on a triangle): Newton's points and Jacobians in a few
/// multiply-adds, where passes over the shape functions and their
/// gradients took a tenth of a run on `impact` (bent quads). `scale`, the
/// largest node coordinate, is what a residual is measured against.
#[derive(Debug, Clone, Copy)]
pub(super) struct Bilinear {
    c: Vec2,
    a1: Vec2,
    a2: Vec2,
    b: Vec2,
    scale: f64,
}

impl Bilinear {
    pub(super) fn of<T: Scalar>(facet: FacetType, nodes: &[[T; 2]]) -> Self {
        let v = |i: usize| [nodes[i][0].re(), nodes[i][1].re()];
        let mut m = [[0.0; 2]; 4];
        match facet.linear() {
            // N_a = ¼ (1 + ξ_a ζ₁)(1 + η_a ζ₂).
            FacetType::Quad4 => {
                for (i, node) in crate::fem::shape::QUAD4_REF_NODES.iter().enumerate() {
                    let weights = [1.0, node[0], node[1], node[0] * node[1]];
                    for (row, w) in m.iter_mut().zip(weights) {
                        row[0] += 0.25 * w * v(i)[0];
                        row[1] += 0.25 * w * v(i)[1];
                    }
                }
            }
            _ => {
                let (v0, v1, v2) = (v(0), v(1), v(2));
                m = [v0, sub(v1, v0), sub(v2, v0), [0.0, 0.0]];
            }
        }
        let scale = (0..facet.nodes())
            .map(|i| v(i)[0].abs().max(v(i)[1].abs()))
            .fold(0.0, f64::max)
            .max(f64::MIN_POSITIVE);
        let [c, a1, a2, b] = m;
        Bilinear {
            c,
            a1,
            a2,
            b,
            scale,
        }
    }

    /// The bilinear term's size relative to the largest node coordinate,
    /// `|x₀ − x₁ + x₂ − x₃| / scale` (zero for a triangle or a
    /// parallelogram: the map is then affine).
    pub(super) fn relative_bilinear_term(&self) -> f64 {
        4.0 * self.b[0].hypot(self.b[1]) / self.scale
    }

    /// How far the map is from affine, free of the facet's position and
    /// size: `|b| / √|a₁ × a₂|`, the bilinear term against the square root
    /// of the mean Jacobian (zero for a triangle or a parallelogram).
    pub(super) fn distortion(&self) -> f64 {
        let area = (self.a1[0] * self.a2[1] - self.a1[1] * self.a2[0]).abs();
        distortion(self.b[0].hypot(self.b[1]), area)
    }

    pub(super) fn at(&self, z: Vec2) -> Vec2 {
        let bz = z[0] * z[1];
        [0, 1].map(|k| self.c[k] + self.a1[k] * z[0] + self.a2[k] * z[1] + self.b[k] * bz)
    }

    /// `(∂x/∂ζ)⁻¹` at `ζ`; `None` if singular.
    pub(super) fn inverse_jacobian(&self, z: Vec2) -> Option<[[f64; 2]; 2]> {
        let j = [0, 1].map(|k| [self.a1[k] + self.b[k] * z[1], self.a2[k] + self.b[k] * z[0]]);
        let det = j[0][0] * j[1][1] - j[0][1] * j[1][0];
        let size = (j[0][0].abs() + j[1][1].abs() + j[0][1].abs() + j[1][0].abs()).powi(2);
        if !(det.abs() > 1e-14 * size && size > 0.0) {
            return None;
        }
        let inv = 1.0 / det;
        Some([
            [j[1][1] * inv, -j[0][1] * inv],
            [-j[1][0] * inv, j[0][0] * inv],
        ])
    }

    /// Newton from `start` for the point mapped onto `target`.
    pub(super) fn newton(&self, target: Vec2, start: Vec2) -> Option<Vec2> {
        let mut zeta = start;
        for _ in 0..30 {
            let r = sub(target, self.at(zeta));
            let inv = self.inverse_jacobian(zeta)?;
            let step = [
                inv[0][0] * r[0] + inv[0][1] * r[1],
                inv[1][0] * r[0] + inv[1][1] * r[1],
            ];
            zeta = [zeta[0] + step[0], zeta[1] + step[1]];
            if step[0].abs().max(step[1].abs()) < 1e-14 {
                return Some(zeta);
            }
            if !(zeta[0].abs() < 10.0 && zeta[1].abs() < 10.0) {
                return None;
            }
        }
        // Accept a residual at rounding level (bilinear Newton stalls there).
        let x = self.at(zeta);
        ((x[0] - target[0]).hypot(x[1] - target[1]) <= 1e-12 * self.scale).then_some(zeta)
    }
}

/// `|b| / √A` for a map's bilinear term `|b|` and mean Jacobian `A`: zero
/// when `b` is zero (a triangle, a parallelogram), infinite for a
/// degenerate facet (no area) with a bilinear term.
pub(super) fn distortion(b: f64, area: f64) -> f64 {
    if b == 0.0 {
        0.0
    } else if area > 0.0 {
        b / area.sqrt()
    } else {
        f64::INFINITY
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The map takes the reference corners to the nodes, Newton inverts it
    /// on a bent quad and a triangle, and the inverse Jacobian is that of
    /// central differences of `at`.
    #[test]
    fn newton_inverts_the_map_and_the_jacobian_matches_differences() {
        let quad = [[0.0, 0.0], [2.0, 0.3], [2.4, 1.9], [-0.2, 1.2]];
        let tri = [[0.1, 0.0], [1.5, 0.2], [0.4, 1.1], [0.0, 0.0]];
        for (facet, nodes, zeta) in [
            (FacetType::Quad4, quad, [0.37, -0.61]),
            (FacetType::Tri3, tri, [0.21, 0.33]),
        ] {
            let map = Bilinear::of::<f64>(facet, &nodes);
            let corners: Vec<Vec2> = match facet {
                FacetType::Quad4 => crate::fem::shape::QUAD4_REF_NODES.to_vec(),
                _ => vec![[0.0, 0.0], [1.0, 0.0], [0.0, 1.0]],
            };
            for (corner, node) in corners.iter().zip(&nodes) {
                let x = map.at(*corner);
                assert!((x[0] - node[0]).abs() + (x[1] - node[1]).abs() < 1e-15);
            }
            let start = crate::contact::projection::reference_centre(facet);
            let found = map.newton(map.at(zeta), start).unwrap();
            assert!((found[0] - zeta[0]).abs() + (found[1] - zeta[1]).abs() < 1e-13);
            let inv = map.inverse_jacobian(zeta).unwrap();
            let h = 1e-6;
            let column = |k: usize| {
                let (mut p, mut m) = (zeta, zeta);
                p[k] += h;
                m[k] -= h;
                let d = sub(map.at(p), map.at(m));
                [d[0] / (2.0 * h), d[1] / (2.0 * h)]
            };
            let (c0, c1) = (column(0), column(1));
            // inv · J = I.
            for (r, row) in inv.iter().enumerate() {
                for (c, col) in [c0, c1].iter().enumerate() {
                    let v = row[0] * col[0] + row[1] * col[1];
                    let want = if r == c { 1.0 } else { 0.0 };
                    assert!((v - want).abs() < 1e-8, "{facet:?} ({r}, {c}): {v}");
                }
            }
        }
    }
}
