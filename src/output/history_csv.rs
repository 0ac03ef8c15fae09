//! The per-step history CSV written next to the result file.

use std::path::{Path, PathBuf};

use crate::error::Result;
use crate::petsc::Vector;
use crate::runtime::Runtime;
use crate::solve::phases::Phase;
use crate::solve::{PairFields, StepReport, StepSink};

/// Per-step history as CSV next to the HDF5 file (rank 0 writes it): load
/// factor, time, Newton, Uzawa and linear iterations and the cutbacks taken
/// before the step converged, each pair's contact force (vector, normal and
/// tangential parts, active and sliding points; a pair with a deformable
/// master also the master facets held per rank, least and most,
/// the most received, and the whole master's), each Dirichlet set's
/// reaction, in dynamics the energies and momentum, and the seconds per
/// phase. One row per converged step, flushed as it goes.
pub struct HistoryCsv {
    out: Option<std::io::BufWriter<std::fs::File>>,
    path: PathBuf,
    header_written: bool,
}

impl HistoryCsv {
    pub fn create(rt: &Runtime, path: &Path) -> Result<Self> {
        let out = if rt.rank() == 0 {
            let f = std::fs::File::create(path).map_err(|e| {
                std::io::Error::new(e.kind(), format!("cannot create {}: {e}", path.display()))
            });
            Some(f.map(std::io::BufWriter::new))
        } else {
            None
        };
        let out = crate::parallel::agree(&rt.world(), out.transpose().map_err(Into::into))?;
        Ok(HistoryCsv {
            out,
            path: path.to_path_buf(),
            header_written: false,
        })
    }

    fn header(report: &StepReport) -> Vec<String> {
        let mut h: Vec<String> = [
            "step",
            "load_factor",
            "time",
            "newton",
            "uzawa",
            "linear",
            "cutbacks",
        ]
        .iter()
        .map(|s| s.to_string())
        .collect();
        for c in &report.contact {
            for k in [
                "fx",
                "fy",
                "fz",
                "normal",
                "tangential",
                "active",
                "sliding",
            ] {
                h.push(format!("{}.{k}", c.name));
            }
            if c.master_held.is_some() {
                for k in [
                    "master_held_min",
                    "master_held_max",
                    "master_received_max",
                    "master_facets",
                ] {
                    h.push(format!("{}.{k}", c.name));
                }
            }
        }
        for (i, (set, _)) in report.reactions.iter().enumerate() {
            for k in ["rx", "ry", "rz"] {
                h.push(format!("dirichlet{i}:{set}.{k}"));
            }
        }
        if report.dynamics.is_some() {
            for k in ["kinetic", "strain", "px", "py", "pz"] {
                h.push(k.to_string());
            }
        }
        h.extend(Phase::ALL.iter().map(|p| p.key().to_string()));
        h
    }

    fn row(report: &StepReport) -> Vec<String> {
        let time = report.dynamics.map_or(report.load_factor, |d| d.time);
        let mut r = vec![
            report.index.to_string(),
            format!("{:.12e}", report.load_factor),
            format!("{time:.12e}"),
            report.newton_iterations.to_string(),
            report.uzawa_iterations.to_string(),
            report.linear_iterations.to_string(),
            report.cutbacks.to_string(),
        ];
        let num = |v: f64| format!("{v:.12e}");
        for c in &report.contact {
            r.extend(c.force.iter().map(|v| num(*v)));
            r.push(num(c.normal_force));
            r.push(num(c.tangential_force));
            r.push(c.active_points.to_string());
            r.push(c.sliding_points.to_string());
            if let Some(held) = c.master_held {
                r.extend(held.iter().map(|n| n.to_string()));
            }
        }
        for (_, f) in &report.reactions {
            r.extend(f.iter().map(|v| num(*v)));
        }
        if let Some(d) = &report.dynamics {
            r.push(num(d.kinetic));
            r.push(num(d.strain));
            r.extend(d.momentum.iter().map(|v| num(*v)));
        }
        r.extend(
            Phase::ALL
                .iter()
                .map(|&p| format!("{:.6e}", report.phases.get(p))),
        );
        r
    }
}

impl StepSink for HistoryCsv {
    fn step(
        &mut self,
        report: &StepReport,
        _: &Vector,
        _: &Vector,
        _: &[PairFields],
        _: &[f64],
        _: Option<&Vector>,
    ) -> Result<()> {
        use std::io::Write;
        let Some(out) = &mut self.out else {
            return Ok(());
        };
        let mut write = || -> std::io::Result<()> {
            if !self.header_written {
                writeln!(out, "{}", Self::header(report).join(","))?;
            }
            writeln!(out, "{}", Self::row(report).join(","))?;
            out.flush()
        };
        // Only rank 0 writes, so a failure here must not end the run (the
        // other ranks would wait in the next collective): warn and stop.
        match write() {
            Ok(()) => self.header_written = true,
            Err(e) => {
                eprintln!(
                    "contactlink: warning: writing {} failed ({e}); no further history rows",
                    self.path.display()
                );
                self.out = None;
            }
        }
        Ok(())
    }
}
