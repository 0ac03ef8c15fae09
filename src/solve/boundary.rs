//! Dirichlet conditions as this rank's constrained DOFs.
use crate::amplitude::Amplitude;
use crate::dofs::{DofMap, NaturalNode, DIM};
use crate::error::{Error, Result};
use crate::model::DirichletSpec;
use std::collections::BTreeMap;

/// A constrained DOF this rank owns.
#[derive(Debug, Clone, Copy)]
pub struct ConstrainedDof {
    /// Index into this rank's owned part of a PETSc vector.
    pub owned_index: usize,
    pub global: i32,
    /// Displacement at load factor 1.
    pub value: f64,
}

/// The owned constrained DOFs (sorted by owned index) and, for reporting, the
/// set each belongs to.
#[derive(Debug, Clone, Default)]
pub struct Dirichlet {
    pub dofs: Vec<ConstrainedDof>,
    pub set_of_dof: Vec<u16>,
    pub set_names: Vec<String>,
    /// Amplitude of each set.
    pub amplitudes: Vec<Amplitude>,
}

impl Dirichlet {
    /// Collects the owned DOFs fixed by `specs`. Two conditions prescribing
    /// different values on one DOF are an error naming both sets.
    pub fn new(dofs: &DofMap, specs: &[DirichletSpec]) -> Result<Self> {
        let mut by_index: BTreeMap<usize, (ConstrainedDof, u16)> = BTreeMap::new();
        let start = dofs.owned_dof_start();
        for (s, spec) in specs.iter().enumerate() {
            for (&nat, node_value) in spec.nodes.iter().zip(&spec.values) {
                let Some(l) = dofs.local(NaturalNode(nat)) else {
                    continue;
                };
                if !dofs.is_owned(l) {
                    continue;
                }
                for &c in &spec.components {
                    let value = node_value[c];
                    let g = dofs.dof(l, c);
                    let owned_index = g.0 as usize - start;
                    let entry = ConstrainedDof {
                        owned_index,
                        global: g.0,
                        value,
                    };
                    if let Some((prev, ps)) = by_index.get(&owned_index) {
                        if (prev.value - value).abs() > 1e-14 * (1.0 + value.abs()) {
                            return Err(Error::scene(
                                "dirichlet",
                                format!(
                                    "node {nat} component {} is prescribed {} by set '{}' and {} by set '{}'",
                                    ["x", "y", "z"][c],
                                    prev.value,
                                    specs[*ps as usize].set,
                                    value,
                                    spec.set
                                ),
                            ));
                        }
                    }
                    by_index.insert(owned_index, (entry, s as u16));
                }
            }
        }
        let (dofs_v, sets): (Vec<_>, Vec<_>) = by_index.into_values().unzip();
        Ok(Dirichlet {
            dofs: dofs_v,
            set_of_dof: sets,
            set_names: specs.iter().map(|s| s.set.clone()).collect(),
            amplitudes: specs.iter().map(|s| s.amplitude.clone()).collect(),
        })
    }

    pub fn global_rows(&self) -> Vec<i32> {
        self.dofs.iter().map(|d| d.global).collect()
    }

    /// Writes the prescribed values at load factor `factor` into owned entries.
    pub fn apply(&self, owned: &mut [f64], factor: f64) {
        for (d, a) in self.with_amplitude(factor) {
            owned[d.owned_index] = a * d.value;
        }
    }

    /// The largest change of a prescribed displacement component on this
    /// rank's constrained DOFs from load factor `from` to `to`.
    pub fn largest_increment(&self, from: f64, to: f64) -> f64 {
        self.with_amplitude(to)
            .zip(self.with_amplitude(from))
            .map(|((d, a), (_, b))| ((a - b) * d.value).abs())
            .fold(0.0, f64::max)
    }

    /// Replaces constrained residual entries by x − ū(factor).
    pub fn constrain_residual(&self, x: &[f64], r: &mut [f64], factor: f64) {
        for (d, a) in self.with_amplitude(factor) {
            r[d.owned_index] = x[d.owned_index] - a * d.value;
        }
    }

    fn with_amplitude(&self, factor: f64) -> impl Iterator<Item = (&ConstrainedDof, f64)> {
        let amp: Vec<f64> = self.amplitudes.iter().map(|a| a.at(factor)).collect();
        self.dofs
            .iter()
            .zip(&self.set_of_dof)
            .map(move |(d, &s)| (d, amp[s as usize]))
    }

    /// Sum of the reaction force over each set's owned DOFs on this rank
    /// (the caller reduces over ranks). `raw` is f_int − f_ext.
    pub fn reaction_sums(&self, raw: &[f64], start_dof: usize) -> Vec<[f64; 3]> {
        let mut sums = vec![[0.0; 3]; self.set_names.len()];
        for (d, &s) in self.dofs.iter().zip(&self.set_of_dof) {
            let c = (d.global as usize - start_dof) % DIM;
            sums[s as usize][c] += raw[d.owned_index];
        }
        sums
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn dof(owned_index: usize, value: f64) -> ConstrainedDof {
        ConstrainedDof {
            owned_index,
            global: owned_index as i32,
            value,
        }
    }

    #[test]
    fn largest_increment_follows_each_sets_amplitude() {
        // Set 0 ramps (a(f) = f), set 1 holds still until f = 0.5 and then
        // reaches 1 at f = 1.
        let late = Amplitude::from_table(&[[0.0, 0.0], [0.5, 0.0], [1.0, 1.0]]).unwrap();
        let d = Dirichlet {
            dofs: vec![dof(0, -0.2), dof(1, 0.05), dof(2, 1.0)],
            set_of_dof: vec![0, 0, 1],
            set_names: vec!["top".into(), "side".into()],
            amplitudes: vec![Amplitude::ramp(), late],
        };
        // 0 -> 0.5: only the ramp moves, |−0.2| · 0.5.
        assert!((d.largest_increment(0.0, 0.5) - 0.1).abs() < 1e-15);
        // 0.5 -> 1: the late set moves 1.0, the ramp 0.1.
        assert!((d.largest_increment(0.5, 1.0) - 1.0).abs() < 1e-15);
        // No step, no motion; none without constrained DOFs.
        assert_eq!(d.largest_increment(0.7, 0.7), 0.0);
        assert_eq!(Dirichlet::default().largest_increment(0.0, 1.0), 0.0);
    }
}
