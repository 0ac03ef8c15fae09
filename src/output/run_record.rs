//! The run's totals in its result file: `/run` (what the `done:` and
//! `solver:` summary lines print) and the last step's Hertz comparison as
//! attributes of `/hertz` (the `Hertz:` lines). Written by rank 0 alone once
//! the run has closed the file (the totals are known only then), read back
//! by [`read_run_record`] and [`read_hertz_record`]: tests and benchmark
//! scripts read these, not the printed text.

use std::path::Path;

use hdf5::types::VarLenUnicode;

use super::{layout, read_f64_attr, read_string_attr, OutputError};
use crate::hertz::HertzComparison;
use crate::solve::RunReport;

/// What `/run` holds.
#[derive(Debug, Clone, Default, PartialEq)]
pub struct RunRecord {
    pub ranks: usize,
    pub dofs: usize,
    pub steps: usize,
    /// Summed over the converged steps.
    pub newton_iterations: usize,
    pub uzawa_iterations: usize,
    pub linear_iterations: usize,
    /// Cutbacks taken before a step converged, summed over the steps.
    pub cutbacks: usize,
    /// The run's solve seconds (the `done:` line's).
    pub wall_seconds: f64,
    pub bulk_tangent_assemblies: usize,
    pub pattern_builds: usize,
    pub preconditioner_builds: usize,
    pub preconditioner_reuses: usize,
    /// The contact Schur path's counts; None when the run did not take it.
    pub schur: Option<SchurRecord>,
}

/// The contact Schur path's counts in `/run`.
#[derive(Debug, Clone, Copy, Default, PartialEq, Eq)]
pub struct SchurRecord {
    /// Several ranks (K's factor with a low-rank update) or one.
    pub low_rank: bool,
    pub dofs: usize,
    pub bulk_factorisations: usize,
    pub schur_factorisations: usize,
    pub growths: usize,
    pub sparse_solves: usize,
    pub dense_solves: usize,
}

impl RunRecord {
    /// The record of a run on `ranks` ranks.
    pub fn of(report: &RunReport, ranks: usize) -> Self {
        let sum = |f: fn(&crate::solve::StepReport) -> usize| report.steps.iter().map(f).sum();
        RunRecord {
            ranks,
            dofs: report.global_dofs,
            steps: report.steps.len(),
            newton_iterations: sum(|s| s.newton_iterations),
            uzawa_iterations: sum(|s| s.uzawa_iterations),
            linear_iterations: sum(|s| s.linear_iterations),
            cutbacks: sum(|s| s.cutbacks),
            wall_seconds: report.wall_seconds,
            bulk_tangent_assemblies: report.bulk_tangent_assemblies,
            pattern_builds: report.pattern_builds,
            preconditioner_builds: report.preconditioner_builds,
            preconditioner_reuses: report.preconditioner_reuses,
            schur: report.schur.map(|s| SchurRecord {
                low_rank: s.low_rank,
                dofs: s.dofs,
                bulk_factorisations: s.bulk_factorisations,
                schur_factorisations: s.schur_factorisations,
                growths: s.growths,
                sparse_solves: s.sparse_solves,
                dense_solves: s.dense_solves,
            }),
        }
    }

    fn counts(&self) -> Vec<(&'static str, usize)> {
        let mut c = vec![
            (layout::RUN_RANKS_ATTR, self.ranks),
            (layout::RUN_DOFS_ATTR, self.dofs),
            (layout::RUN_STEPS_ATTR, self.steps),
            (layout::NEWTON_ATTR, self.newton_iterations),
            (layout::UZAWA_ATTR, self.uzawa_iterations),
            (layout::LINEAR_ATTR, self.linear_iterations),
            (layout::CUTBACKS_ATTR, self.cutbacks),
            (
                layout::BULK_TANGENT_ASSEMBLIES_ATTR,
                self.bulk_tangent_assemblies,
            ),
            (layout::PATTERN_BUILDS_ATTR, self.pattern_builds),
            (
                layout::PRECONDITIONER_BUILDS_ATTR,
                self.preconditioner_builds,
            ),
            (
                layout::PRECONDITIONER_REUSES_ATTR,
                self.preconditioner_reuses,
            ),
        ];
        if let Some(s) = &self.schur {
            c.extend([
                (layout::SCHUR_DOFS_ATTR, s.dofs),
                (layout::BULK_FACTORISATIONS_ATTR, s.bulk_factorisations),
                (layout::SCHUR_FACTORISATIONS_ATTR, s.schur_factorisations),
                (layout::SCHUR_GROWTHS_ATTR, s.growths),
                (layout::SPARSE_SOLVES_ATTR, s.sparse_solves),
                (layout::DENSE_SOLVES_ATTR, s.dense_solves),
            ]);
        }
        c
    }

    fn schur_path(&self) -> &'static str {
        match self.schur {
            None => layout::SCHUR_PATH_NONE,
            Some(s) if s.low_rank => layout::SCHUR_PATH_LOW_RANK,
            Some(_) => layout::SCHUR_PATH_ONE_RANK,
        }
    }
}

/// Adds `/run` (and, with a Hertz comparison, its figures on `/hertz`) to
/// the closed result file `path`. Serial: one process only.
pub fn write_run_record(
    path: &Path,
    record: &RunRecord,
    hertz: Option<&HertzComparison>,
) -> Result<(), OutputError> {
    let file = hdf5::File::open_rw(path).map_err(|source| OutputError::Open {
        path: path.to_path_buf(),
        source,
    })?;
    let group = |name: &str, object: &str| {
        if file.link_exists(name) {
            file.group(name)
                .map_err(|e| OutputError::hdf5(path, object, "open", e))
        } else {
            file.create_group(name)
                .map_err(|e| OutputError::hdf5(path, object, "create", e))
        }
    };
    let run = group(layout::RUN_NAME, layout::RUN)?;
    let fail = |object: &'static str| move |e| OutputError::hdf5(path, object, "write", e);
    for (name, value) in record.counts() {
        replace_attr(&run, name).map_err(fail(layout::RUN))?;
        let value = i64::try_from(value).unwrap_or(i64::MAX);
        run.new_attr::<i64>()
            .create(name)
            .and_then(|a| a.write_scalar(&value))
            .map_err(fail(layout::RUN))?;
    }
    write_f64s(&run, &[(layout::WALL_SECONDS_ATTR, record.wall_seconds)])
        .map_err(fail(layout::RUN))?;
    replace_attr(&run, layout::SCHUR_PATH_ATTR).map_err(fail(layout::RUN))?;
    let text: VarLenUnicode = record
        .schur_path()
        .parse()
        .map_err(|e| OutputError::invalid(path, layout::RUN, format!("{e}")))?;
    run.new_attr::<VarLenUnicode>()
        .create(layout::SCHUR_PATH_ATTR)
        .and_then(|a| a.write_scalar(&text))
        .map_err(fail(layout::RUN))?;
    if let Some(h) = hertz {
        let g = group(layout::HERTZ.trim_start_matches('/'), layout::HERTZ)?;
        let mut values = vec![
            (layout::HERTZ_LOAD_ATTR, h.load),
            (layout::HERTZ_P0_ATTR, h.p0),
            (layout::HERTZ_P0_EXACT_ATTR, h.p0_exact),
            (layout::HERTZ_WIDTH_ATTR, h.width),
            (layout::HERTZ_WIDTH_EXACT_ATTR, h.width_exact),
            (layout::HERTZ_P0_ERROR_ATTR, h.p0_error()),
            (layout::HERTZ_WIDTH_ERROR_ATTR, h.width_error()),
        ];
        if let Some((p0, width)) = h.averaged_errors() {
            values.push((layout::HERTZ_P0_ERROR_AVERAGED_ATTR, p0));
            values.push((layout::HERTZ_WIDTH_ERROR_AVERAGED_ATTR, width));
        }
        write_f64s(&g, &values).map_err(fail(layout::HERTZ))?;
    }
    Ok(())
}

fn replace_attr(g: &hdf5::Group, name: &str) -> hdf5::Result<()> {
    if g.attr(name).is_ok() {
        g.delete_attr(name)?;
    }
    Ok(())
}

fn write_f64s(g: &hdf5::Group, values: &[(&str, f64)]) -> hdf5::Result<()> {
    for (name, value) in values {
        replace_attr(g, name)?;
        g.new_attr::<f64>()
            .create(*name)
            .and_then(|a| a.write_scalar(value))?;
    }
    Ok(())
}

/// `/run` of a result file; None in a file without it (a run that did not
/// end, or an older file).
pub fn read_run_record(path: &Path) -> Result<Option<RunRecord>, OutputError> {
    let file = hdf5::File::open(path).map_err(|source| OutputError::Open {
        path: path.to_path_buf(),
        source,
    })?;
    if !file.link_exists(layout::RUN_NAME) {
        return Ok(None);
    }
    let run = file
        .group(layout::RUN_NAME)
        .map_err(|e| OutputError::hdf5(path, layout::RUN, "open", e))?;
    let count = |name: &str| -> Result<usize, OutputError> {
        let v = run
            .attr(name)
            .and_then(|a| a.read_scalar::<i64>())
            .map_err(|e| OutputError::hdf5(path, layout::RUN, "read attributes of", e))?;
        usize::try_from(v).map_err(|_| {
            OutputError::invalid(path, layout::RUN, format!("{name} = {v} is negative"))
        })
    };
    let schur_path = read_string_attr(path, layout::RUN, layout::SCHUR_PATH_ATTR)?;
    let schur = match schur_path.as_deref() {
        None | Some(layout::SCHUR_PATH_NONE) => None,
        Some(p) => Some(SchurRecord {
            low_rank: p == layout::SCHUR_PATH_LOW_RANK,
            dofs: count(layout::SCHUR_DOFS_ATTR)?,
            bulk_factorisations: count(layout::BULK_FACTORISATIONS_ATTR)?,
            schur_factorisations: count(layout::SCHUR_FACTORISATIONS_ATTR)?,
            growths: count(layout::SCHUR_GROWTHS_ATTR)?,
            sparse_solves: count(layout::SPARSE_SOLVES_ATTR)?,
            dense_solves: count(layout::DENSE_SOLVES_ATTR)?,
        }),
    };
    Ok(Some(RunRecord {
        ranks: count(layout::RUN_RANKS_ATTR)?,
        dofs: count(layout::RUN_DOFS_ATTR)?,
        steps: count(layout::RUN_STEPS_ATTR)?,
        newton_iterations: count(layout::NEWTON_ATTR)?,
        uzawa_iterations: count(layout::UZAWA_ATTR)?,
        linear_iterations: count(layout::LINEAR_ATTR)?,
        cutbacks: count(layout::CUTBACKS_ATTR)?,
        wall_seconds: read_f64_attr(path, layout::RUN, layout::WALL_SECONDS_ATTR)?.unwrap_or(0.0),
        bulk_tangent_assemblies: count(layout::BULK_TANGENT_ASSEMBLIES_ATTR)?,
        pattern_builds: count(layout::PATTERN_BUILDS_ATTR)?,
        preconditioner_builds: count(layout::PRECONDITIONER_BUILDS_ATTR)?,
        preconditioner_reuses: count(layout::PRECONDITIONER_REUSES_ATTR)?,
        schur,
    }))
}

/// The last step's Hertz comparison as the run wrote it on `/hertz`: the
/// relative errors of p0 and of the width (point reading), and read as
/// nodal averages when that fit succeeded. None without one.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct HertzRecord {
    pub load: f64,
    pub p0: f64,
    pub p0_exact: f64,
    pub width: f64,
    pub width_exact: f64,
    pub p0_error: f64,
    pub width_error: f64,
    pub averaged_errors: Option<(f64, f64)>,
}

/// `/hertz`'s comparison figures; None when the file has none.
pub fn read_hertz_record(path: &Path) -> Result<Option<HertzRecord>, OutputError> {
    let get = |name: &str| read_f64_attr(path, layout::HERTZ, name);
    let (Some(load), Some(p0)) = (get(layout::HERTZ_LOAD_ATTR)?, get(layout::HERTZ_P0_ATTR)?)
    else {
        return Ok(None);
    };
    let need = |name: &str| -> Result<f64, OutputError> {
        get(name)?.ok_or_else(|| OutputError::invalid(path, layout::HERTZ, format!("no {name}")))
    };
    let averaged = match (
        get(layout::HERTZ_P0_ERROR_AVERAGED_ATTR)?,
        get(layout::HERTZ_WIDTH_ERROR_AVERAGED_ATTR)?,
    ) {
        (Some(p), Some(w)) => Some((p, w)),
        _ => None,
    };
    Ok(Some(HertzRecord {
        load,
        p0,
        p0_exact: need(layout::HERTZ_P0_EXACT_ATTR)?,
        width: need(layout::HERTZ_WIDTH_ATTR)?,
        width_exact: need(layout::HERTZ_WIDTH_EXACT_ATTR)?,
        p0_error: need(layout::HERTZ_P0_ERROR_ATTR)?,
        width_error: need(layout::HERTZ_WIDTH_ERROR_ATTR)?,
        averaged_errors: averaged,
    }))
}
