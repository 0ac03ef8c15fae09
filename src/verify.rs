//! Closed-form answers (docs/formulation.md §12) and the post-processing that compares a
//! run against them: Hertz line and point contact.
use std::f64::consts::PI;

/// Which Hertz problem a scene reproduces.
#[derive(Debug, Clone, PartialEq)]
pub enum HertzKind {
    /// Cylinder on a flat, plane strain; the load per unit length is the
    /// contact force divided by `thickness`.
    Line { thickness: f64 },
    /// Sphere on a flat.
    Point,
}

/// A scene's request to compare a contact pair against Hertz.
#[derive(Debug, Clone, PartialEq)]
pub struct HertzCheck {
    pub kind: HertzKind,
    pub pair: String,
    pub radius: f64,
    /// E* = 1/((1−ν₁²)/E₁ + (1−ν₂²)/E₂), from the two bodies' materials.
    pub effective_modulus: f64,
}

/// Computed against analytic peak pressure and contact half-width (line) or radius (point).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct HertzComparison {
    pub load: f64,
    pub p0: f64,
    pub p0_exact: f64,
    pub width: f64,
    pub width_exact: f64,
}

impl HertzComparison {
    pub fn p0_error(&self) -> f64 {
        (self.p0 - self.p0_exact) / self.p0_exact
    }

    pub fn width_error(&self) -> f64 {
        (self.width - self.width_exact) / self.width_exact
    }
}

pub fn effective_modulus(e1: f64, nu1: f64, e2: f64, nu2: f64) -> f64 {
    1.0 / ((1.0 - nu1 * nu1) / e1 + (1.0 - nu2 * nu2) / e2)
}

/// Line contact: (b, p0) for a load P per unit length.
pub fn hertz_line(p: f64, radius: f64, e_star: f64) -> (f64, f64) {
    let b = (4.0 * p * radius / (PI * e_star)).sqrt();
    (b, 2.0 * p / (PI * b))
}

/// Point contact: (a, p0) for a total force F.
pub fn hertz_point(f: f64, radius: f64, e_star: f64) -> (f64, f64) {
    let a = (3.0 * f * radius / (4.0 * e_star)).cbrt();
    (a, 3.0 * f / (2.0 * PI * a * a))
}

/// Fits the Hertz profile p² = p0² (1 − s²/w²) to contact-point pressures,
/// s the distance from the profile's centre (|x| for a line contact along y,
/// √(x²+y²) for a point contact), by linear least squares in (s², p²) over
/// the points inside 90 % of the loaded zone (the edge is where a discrete
/// solution departs most from the square-root profile). Returns (p0, w).
pub fn fit_profile(kind: &HertzKind, points: &[[f64; 3]], pressure: &[f64]) -> Option<(f64, f64)> {
    let loaded: Vec<(f64, f64)> = points
        .iter()
        .zip(pressure)
        .filter(|(_, &p)| p > 0.0)
        .map(|(x, &p)| (radial2(kind, x), p))
        .collect();
    let s2_max = loaded.iter().map(|(s2, _)| *s2).fold(0.0, f64::max);
    if loaded.len() < 3 || s2_max <= 0.0 {
        return None;
    }
    let inner: Vec<(f64, f64)> = loaded
        .into_iter()
        .filter(|(s2, _)| *s2 <= 0.81 * s2_max)
        .map(|(s2, p)| (s2, p * p))
        .collect();
    let n = inner.len() as f64;
    if n < 3.0 {
        return None;
    }
    let (sx, sy) = inner
        .iter()
        .fold((0.0, 0.0), |(a, b), (x, y)| (a + x, b + y));
    let (mx, my) = (sx / n, sy / n);
    let (sxx, sxy) = inner.iter().fold((0.0, 0.0), |(a, b), (x, y)| {
        (a + (x - mx) * (x - mx), b + (x - mx) * (y - my))
    });
    if sxx <= 0.0 {
        return None;
    }
    let slope = sxy / sxx;
    let intercept = my - slope * mx;
    if intercept <= 0.0 || slope >= 0.0 {
        return None;
    }
    let p0 = intercept.sqrt();
    Some((p0, (intercept / -slope).sqrt()))
}

fn radial2(kind: &HertzKind, x: &[f64; 3]) -> f64 {
    match kind {
        HertzKind::Line { .. } => x[0] * x[0],
        HertzKind::Point => x[0] * x[0] + x[1] * x[1],
    }
}

/// Compares a pair's pressures and total force against Hertz.
pub fn compare(
    check: &HertzCheck,
    points: &[[f64; 3]],
    pressure: &[f64],
    force: [f64; 3],
) -> Option<HertzComparison> {
    let total = (force[0] * force[0] + force[1] * force[1] + force[2] * force[2]).sqrt();
    let (load, (width_exact, p0_exact)) = match check.kind {
        HertzKind::Line { thickness } => {
            let p = total / thickness;
            (p, hertz_line(p, check.radius, check.effective_modulus))
        }
        HertzKind::Point => (
            total,
            hertz_point(total, check.radius, check.effective_modulus),
        ),
    };
    let (p0, width) = fit_profile(&check.kind, points, pressure)?;
    Some(HertzComparison {
        load,
        p0,
        p0_exact,
        width,
        width_exact,
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn line_formulas_are_consistent() {
        // P = π b p0 / 2 for the elliptical profile.
        let (b, p0) = hertz_line(43.0, 10.0, 549.45);
        assert!((PI * b * p0 / 2.0 - 43.0).abs() < 1e-12);
    }

    #[test]
    fn point_formulas_integrate_to_the_force() {
        // F = 2/3 π a² p0 for the hemispherical profile.
        let (a, p0) = hertz_point(100.0, 10.0, 549.45);
        assert!((2.0 / 3.0 * PI * a * a * p0 - 100.0).abs() < 1e-10);
    }

    #[test]
    fn fit_recovers_an_exact_profile() {
        let (p0, b) = (27.3, 1.04);
        let points: Vec<[f64; 3]> = (0..400)
            .map(|i| [-1.5 + 3.0 * i as f64 / 399.0, 0.5, 0.0])
            .collect();
        let pressure: Vec<f64> = points
            .iter()
            .map(|x| p0 * (1.0 - x[0] * x[0] / (b * b)).max(0.0).sqrt())
            .collect();
        let (fp0, fb) =
            fit_profile(&HertzKind::Line { thickness: 1.0 }, &points, &pressure).unwrap();
        assert!(
            (fp0 - p0).abs() < 1e-9 * p0 && (fb - b).abs() < 1e-9 * b,
            "{fp0} {fb}"
        );
    }

    #[test]
    fn fit_of_nothing_is_none() {
        assert!(fit_profile(&HertzKind::Point, &[[0.0; 3]; 2], &[0.0; 2]).is_none());
    }
}
