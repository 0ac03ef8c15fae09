//! What a pair's contact did on this rank in one evaluation: the Uzawa
//! update's statistics and the contact force. Both formulations (links and
//! mortar) report through these, so they live below both.

/// What an Uzawa update found on this rank (reduced over ranks by the caller).
#[derive(Debug, Clone, Copy, Default)]
pub struct UzawaStats {
    /// Largest penetration relative to the local element size.
    pub max_penetration: f64,
    /// Largest change of a slave node's normal contact force in this update ...
    pub max_change: f64,
    /// ... and the largest nodal contact force after it.
    pub max_force: f64,
    pub max_multiplier: f64,
    pub active: usize,
    /// Points sliding (friction), of the `active` ones.
    pub sliding: usize,
}

/// A pair's contact force on the slave surface (this rank's part, or the
/// total): the vector, and in the contact frame the normal force Σ pN w and
/// the tangential force Σ |tT| w (μ times the normal force when every active
/// point slides).
#[derive(Debug, Clone, Copy, Default, PartialEq)]
pub struct PairForce {
    pub force: [f64; 3],
    pub normal: f64,
    pub tangential: f64,
}

impl PairForce {
    pub fn to_array(self) -> [f64; 5] {
        let [x, y, z] = self.force;
        [x, y, z, self.normal, self.tangential]
    }

    pub fn from_array(a: [f64; 5]) -> Self {
        PairForce {
            force: [a[0], a[1], a[2]],
            normal: a[3],
            tangential: a[4],
        }
    }
}
