//! Load paths: how a load, a prescribed displacement or a rigid master's
//! motion follows the load factor (in dynamics the load factor is t/t_end).
//! Without one, everything ramps linearly from 0 to its full value.

/// A piecewise-linear amplitude `a(f)` given by points `(f_i, a_i)` with
/// increasing `f_i`; constant beyond the first and last point.
#[derive(Debug, Clone, PartialEq)]
pub struct Amplitude {
    points: Vec<(f64, f64)>,
}

impl Default for Amplitude {
    fn default() -> Self {
        Amplitude::ramp()
    }
}

impl Amplitude {
    /// `a(f) = f`.
    pub fn ramp() -> Self {
        Amplitude {
            points: vec![(0.0, 0.0), (1.0, 1.0)],
        }
    }

    /// From a table `[[f, a], ...]`; the error says what is wrong with it.
    pub fn from_table(table: &[[f64; 2]]) -> Result<Self, String> {
        if table.is_empty() {
            return Err("an amplitude needs at least one [load_factor, value] point".into());
        }
        if let Some(p) = table
            .iter()
            .find(|p| !(p[0].is_finite() && p[1].is_finite()))
        {
            return Err(format!("amplitude point {p:?} is not finite"));
        }
        if let Some(w) = table.windows(2).find(|w| w[1][0] <= w[0][0]) {
            return Err(format!(
                "amplitude load factors must increase (got {} after {})",
                w[1][0], w[0][0]
            ));
        }
        Ok(Amplitude {
            points: table.iter().map(|p| (p[0], p[1])).collect(),
        })
    }

    /// The points `(f_i, a_i)`, in increasing `f_i`.
    pub fn points(&self) -> &[(f64, f64)] {
        &self.points
    }

    /// The value at load factor `f`.
    pub fn at(&self, f: f64) -> f64 {
        let pts = &self.points;
        let (first, last) = (pts[0], pts[pts.len() - 1]);
        if f <= first.0 {
            return first.1;
        }
        if f >= last.0 {
            return last.1;
        }
        let i = pts.partition_point(|p| p.0 <= f);
        let ((f0, a0), (f1, a1)) = (pts[i - 1], pts[i]);
        a0 + (a1 - a0) * (f - f0) / (f1 - f0)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn interpolates_and_holds_beyond_the_ends() {
        let a = Amplitude::from_table(&[[0.0, 0.0], [0.5, 1.0], [1.0, 1.0]]).unwrap();
        assert_eq!(a.at(0.25), 0.5);
        assert_eq!(a.at(0.75), 1.0);
        assert_eq!(a.at(2.0), 1.0);
        assert_eq!(a.at(-1.0), 0.0);
        assert_eq!(Amplitude::ramp().at(0.3), 0.3);
        let step = Amplitude::from_table(&[[0.5, 0.0], [1.0, 2.0]]).unwrap();
        assert_eq!(step.at(0.2), 0.0);
        assert_eq!(step.at(0.75), 1.0);
    }

    #[test]
    fn bad_tables_are_rejected() {
        assert!(Amplitude::from_table(&[]).is_err());
        assert!(Amplitude::from_table(&[[0.0, 0.0], [0.0, 1.0]]).is_err());
        assert!(Amplitude::from_table(&[[0.0, f64::NAN]]).is_err());
    }
}
