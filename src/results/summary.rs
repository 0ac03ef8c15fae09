//! `contactlink summary OUT.h5`: one row per step with the solver effort
//! and, per contact pair, the total force, the normal force Σ pN·w, the
//! contact area Σ w (pN > 0), the peak pressure, the active constraints and,
//! with friction, how many of them stick and slip.
use super::{nodal_pressure, open_steps, pair_names, slave_nodes, PairPoints, ResultsError};
use crate::dofs::NaturalNode;
use crate::output::{read_step_attrs, StepInfo};
use std::collections::BTreeMap;
use std::path::Path;

/// One contact pair at one step.
#[derive(Debug, Clone, PartialEq)]
pub struct PairRow {
    pub name: String,
    pub force: [f64; 3],
    /// Σ pN·w (NaN when the file has no point weights).
    pub normal: f64,
    /// Σ w over points with pN > 0 (NaN when the file has no point
    /// weights); a mortar pair: Σ A_j = ∫ N_j dA over its active slave nodes.
    pub area: f64,
    /// Largest nodal contact pressure on the pair's slave nodes: the field
    /// `run`'s Hertz comparison fits (NaN when the file lacks the
    /// pair → slave set map).
    pub max_pressure: f64,
    /// Largest multiplier λN at a quadrature point. The point values of an
    /// over-constrained slave surface oscillate; their nodal sums do not.
    pub max_point_pressure: f64,
    /// Active contact points (links) or active slave nodes (mortar: its
    /// point values are interpolated from the nodes, so a point next to an
    /// active node is positive without being a constraint).
    pub active: usize,
    /// With friction: of the constraints in contact, how many stick and
    /// slip (points or slave nodes, as `active`); None without friction.
    pub friction: Option<super::StickSlip>,
}

/// One step of the result file.
#[derive(Debug, Clone, PartialEq)]
pub struct StepRow {
    pub info: StepInfo,
    pub pairs: Vec<PairRow>,
}

/// Reads every step of `path`.
pub fn summarize(path: &Path) -> Result<Vec<StepRow>, ResultsError> {
    let steps = open_steps(path)?;
    // Each pair's slave nodes, read once (the mesh does not change).
    let mut slaves: BTreeMap<String, Option<Vec<NaturalNode>>> = BTreeMap::new();
    let mut rows = Vec::with_capacity(steps.len());
    for step in steps {
        let info = read_step_attrs(path, step)?;
        let nodal = nodal_pressure(path, step)?;
        let mut pairs = Vec::new();
        for name in pair_names(path, step)? {
            if !slaves.contains_key(&name) {
                slaves.insert(name.clone(), slave_nodes(path, &name)?);
            }
            let nodes = slaves.get(&name).and_then(Option::as_deref);
            let max_nodal = match (nodes, &nodal) {
                (Some(nodes), Some(p)) => nodes
                    .iter()
                    .filter_map(|&NaturalNode(n)| p.get(n).copied())
                    .fold(0.0, f64::max),
                _ => f64::NAN,
            };
            pairs.push(pair_row(path, step, name, max_nodal)?);
        }
        rows.push(StepRow { info, pairs });
    }
    Ok(rows)
}

fn pair_row(
    path: &Path,
    step: usize,
    name: String,
    max_pressure: f64,
) -> Result<PairRow, ResultsError> {
    let p = PairPoints::read(path, step, &name)?;
    let active: Vec<usize> = (0..p.pressure.len()).filter(|&i| p.is_active(i)).collect();
    let (normal, area) = match &p.weight {
        Some(w) => (
            active.iter().map(|&i| p.pressure[i] * w[i]).sum(),
            active.iter().map(|&i| w[i]).sum(),
        ),
        None => (f64::NAN, f64::NAN),
    };
    // A mortar pair's point values are interpolated from its nodes, so
    // every point of a facet with an active corner is positive: its area
    // is that of the active nodes.
    let area = p.active_nodes.map_or(area, |n| n.area);
    Ok(PairRow {
        name,
        force: p.force,
        normal,
        area,
        max_pressure,
        max_point_pressure: p.pressure.iter().copied().fold(0.0, f64::max),
        active: p.active_nodes.map_or(active.len(), |n| n.count),
        friction: p.friction,
    })
}

/// The pairs named in the header: those of the first step (every step of a
/// run writes the same pairs).
fn pair_header(rows: &[StepRow]) -> Vec<&str> {
    rows.first()
        .map(|r| r.pairs.iter().map(|p| p.name.as_str()).collect())
        .unwrap_or_default()
}

/// A fixed-width table for the terminal.
pub fn table(path: &Path, rows: &[StepRow]) -> String {
    let pairs = pair_header(rows);
    let mut out = format!(
        "{}: {} step(s), contact pair(s): {}\n",
        path.display(),
        rows.len(),
        if pairs.is_empty() {
            "none".to_string()
        } else {
            pairs.join(", ")
        }
    );
    let mut head = format!(
        "{:>5} {:>10} {:>12} {:>6} {:>5} {:>8}",
        "step", "load", "time", "newton", "uzawa", "wall s"
    );
    for name in &pairs {
        head += &format!(
            " | {:<34} {:>11} {:>11} {:>11} {:>11} {:>6} {:>6} {:>6}",
            format!("{name}: force [x, y, z]"),
            "normal",
            "area",
            "max p",
            "max λN",
            "active",
            "stick",
            "slip"
        );
    }
    out += head.trim_end();
    out.push('\n');
    for r in rows {
        let i = &r.info;
        let mut line = format!(
            "{:>5} {:>10.4} {:>12.5e} {:>6} {:>5} {:>8.2}",
            i.index, i.load_factor, i.time, i.newton_iterations, i.uzawa_iterations, i.wall_seconds
        );
        for p in &r.pairs {
            let [x, y, z] = p.force;
            let (stick, slip) = p.friction.map_or(("-".into(), "-".into()), |f| {
                (f.stick.to_string(), f.slip.to_string())
            });
            line += &format!(
                " | {:>34} {:>11} {:>11} {:>11} {:>11.4e} {:>6} {stick:>6} {slip:>6}",
                format!("[{x:.3e}, {y:.3e}, {z:.3e}]"),
                number(p.normal),
                number(p.area),
                number(p.max_pressure),
                p.max_point_pressure,
                p.active
            );
        }
        out += &line;
        out.push('\n');
    }
    out
}

/// A quantity that may be unavailable (older files lack point weights).
fn number(v: f64) -> String {
    if v.is_nan() {
        "-".into()
    } else {
        format!("{v:.4e}")
    }
}

/// The same as CSV, full precision; an unavailable quantity is empty.
pub fn csv(rows: &[StepRow]) -> String {
    let pairs = pair_header(rows);
    let mut head: Vec<String> = [
        "step",
        "load_factor",
        "time",
        "newton",
        "uzawa",
        "wall_seconds",
    ]
    .iter()
    .map(|s| s.to_string())
    .collect();
    for name in &pairs {
        for k in [
            "fx",
            "fy",
            "fz",
            "normal",
            "area",
            "max_pressure",
            "max_point_pressure",
            "active",
            "stick",
            "slip",
        ] {
            head.push(format!("{name}.{k}"));
        }
    }
    let mut out = head.join(",") + "\n";
    let num = |v: f64| {
        if v.is_nan() {
            String::new()
        } else {
            format!("{v:.12e}")
        }
    };
    for r in rows {
        let i = &r.info;
        let mut row = vec![
            i.index.to_string(),
            num(i.load_factor),
            num(i.time),
            i.newton_iterations.to_string(),
            i.uzawa_iterations.to_string(),
            num(i.wall_seconds),
        ];
        for p in &r.pairs {
            row.extend(p.force.iter().map(|&v| num(v)));
            row.extend([p.normal, p.area, p.max_pressure, p.max_point_pressure].map(num));
            row.push(p.active.to_string());
            // Empty without friction.
            let count = |c: Option<usize>| c.map_or(String::new(), |c| c.to_string());
            row.push(count(p.friction.map(|f| f.stick)));
            row.push(count(p.friction.map(|f| f.slip)));
        }
        out += &(row.join(",") + "\n");
    }
    out
}

#[cfg(test)]
mod tests {
    use super::*;

    fn rows() -> Vec<StepRow> {
        vec![StepRow {
            info: StepInfo {
                index: 1,
                time: 0.5,
                load_factor: 0.5,
                newton_iterations: 4,
                uzawa_iterations: 2,
                converged: true,
                wall_seconds: 1.25,
            },
            pairs: vec![PairRow {
                name: "hertz".into(),
                force: [0.0, 0.0, 21.5],
                normal: 21.5,
                area: f64::NAN,
                max_pressure: 9.75,
                max_point_pressure: 11.0,
                active: 12,
                friction: None,
            }],
        }]
    }

    #[test]
    fn csv_has_one_column_per_header_entry() {
        let text = csv(&rows());
        let lines: Vec<&str> = text.lines().collect();
        assert_eq!(lines.len(), 2);
        assert_eq!(lines[0].split(',').count(), lines[1].split(',').count());
        assert!(lines[0].contains("hertz.area"));
        // A missing area is an empty field, not "NaN".
        assert!(lines[1].contains(",,"), "{}", lines[1]);
    }

    #[test]
    fn table_marks_missing_values() {
        let t = table(Path::new("x.h5"), &rows());
        assert!(t.starts_with("x.h5: 1 step(s), contact pair(s): hertz"));
        assert!(t.lines().nth(2).is_some_and(|l| l.contains(" - ")), "{t}");
    }
}
