//! `contactlink plot OUT.h5`: the contact pressure of a Hertz scene against
//! the closed form p(s) = p0·√(1 − (s/b)²), as a PNG. The Hertz setup comes
//! from the file's `/hertz` group (written by `run` when the scene has a
//! [hertz] check), the load from the step's total contact force.
use super::{open_steps, slave_nodes, PairPoints, ResultsError};
use crate::dofs::NaturalNode;
use crate::hertz::{self, HertzCheck, HertzKind};
use crate::output::{layout, read_dataset, read_f64_attr, read_nodal, read_string_attr};
use plotters::prelude::*;
use std::collections::HashSet;
use std::path::{Path, PathBuf};

/// Where `plot` looks for a TrueType font (Debian's fonts-dejavu-core);
/// CONTACTLINK_FONT overrides it.
pub const DEFAULT_FONT: &str = "/usr/share/fonts/truetype/dejavu/DejaVuSans.ttf";

/// What was drawn, for the command's one-line report.
#[derive(Debug, Clone)]
pub struct PlotReport {
    pub step: usize,
    pub output: PathBuf,
    /// Computed and closed-form peak pressure and half-width (line) or
    /// radius (point).
    pub comparison: Option<hertz::HertzComparison>,
    /// False when no font was found: the plot has no text.
    pub with_text: bool,
}

/// Draws step `step` (default: the last) of `path` to `output`.
pub fn plot(path: &Path, output: &Path, step: Option<usize>) -> Result<PlotReport, ResultsError> {
    let steps = open_steps(path)?;
    let check = read_hertz_setup(path)?;
    let step = match step {
        None => *steps.last().unwrap_or(&0),
        Some(s) if steps.contains(&s) => s,
        Some(s) => {
            return Err(ResultsError::file(
                path,
                format!(
                    "has no step {s} (steps {}..={})",
                    steps.first().unwrap_or(&0),
                    steps.last().unwrap_or(&0)
                ),
            ))
        }
    };
    let pair = PairPoints::read(path, step, &check.pair)?;
    let nodal = NodalPressure::read(path, step, &check.pair)?;
    let profile = Profile::new(&check, &pair, &nodal);
    // The same comparison `run` prints on its Hertz lines: the profile fitted
    // to the nodal pressures at the reference node positions, read as point
    // values and as nodal averages.
    let loaded: HashSet<[u64; 3]> = nodal.points.iter().map(|x| x.map(f64::to_bits)).collect();
    let samples = super::nodal_samples(path, &check.pair, &|x| {
        loaded.contains(&x.map(f64::to_bits))
    })?
    .unwrap_or_default();
    let comparison = hertz::compare(&check, &nodal.points, &nodal.pressure, &samples, pair.force);
    let font = load_font();
    let with_text = match &font {
        Ok(()) => true,
        Err(why) => {
            eprintln!("contactlink: warning: {why}; drawing the plot without text");
            false
        }
    };
    draw(output, &check, &profile, comparison.as_ref(), with_text)
        .map_err(|e| ResultsError::file(output, format!("cannot draw the plot: {e}")))?;
    Ok(PlotReport {
        step,
        output: output.to_path_buf(),
        comparison,
        with_text,
    })
}

/// The `/hertz` group as a [`HertzCheck`]; a clear error when the file has
/// none (the scene had no [hertz] section, or the file predates it).
pub fn read_hertz_setup(path: &Path) -> Result<HertzCheck, ResultsError> {
    let missing = || {
        ResultsError::Sentence(format!(
            "{} has no Hertz setup; plot draws the Hertz pressure profile only",
            path.display()
        ))
    };
    let text = |k: &str| read_string_attr(path, layout::HERTZ, k);
    let number = |k: &str| read_f64_attr(path, layout::HERTZ, k);
    let kind = text(layout::HERTZ_KIND_ATTR)?.ok_or_else(missing)?;
    let kind = match kind.as_str() {
        layout::HERTZ_KIND_LINE => HertzKind::Line {
            thickness: number(layout::HERTZ_THICKNESS_ATTR)?.ok_or_else(missing)?,
        },
        layout::HERTZ_KIND_POINT => HertzKind::Point,
        other => {
            return Err(ResultsError::file(
                path,
                format!("/hertz kind is '{other}', expected 'line' or 'point'"),
            ))
        }
    };
    Ok(HertzCheck {
        kind,
        pair: text(layout::HERTZ_PAIR_ATTR)?.ok_or_else(missing)?,
        radius: number(layout::HERTZ_RADIUS_ATTR)?.ok_or_else(missing)?,
        effective_modulus: number(layout::HERTZ_EFFECTIVE_MODULUS_ATTR)?.ok_or_else(missing)?,
    })
}

/// The loaded nodes (pN > 0) of the pair's slave surface: reference
/// position and nodal contact pressure.
struct NodalPressure {
    points: Vec<[f64; 3]>,
    pressure: Vec<f64>,
}

impl NodalPressure {
    fn read(path: &Path, step: usize, pair: &str) -> Result<Self, ResultsError> {
        let (nodes, _) = read_dataset::<f64>(path, layout::MESH_NODES)?;
        let (pressure, rows, _) = read_nodal(path, step, layout::CONTACT_PRESSURE)?;
        if nodes.len() != 3 * rows {
            return Err(ResultsError::file(
                path,
                format!(
                    "step {step}: contact_pressure has {rows} rows for {} nodes",
                    nodes.len() / 3
                ),
            ));
        }
        // Without the pair → slave set map (older files) every loaded node
        // counts; a Hertz scene has one pair.
        let ids: Vec<NaturalNode> = match slave_nodes(path, pair)? {
            Some(ids) => ids,
            None => (0..rows).map(NaturalNode).collect(),
        };
        let (points, pressure) = ids
            .into_iter()
            .filter_map(|NaturalNode(n)| Some((nodes.get(3 * n..3 * n + 3)?, *pressure.get(n)?)))
            .filter(|(_, p)| *p > 0.0)
            .map(|(x, p)| ([x[0], x[1], x[2]], p))
            .unzip();
        Ok(NodalPressure { points, pressure })
    }
}

/// The computed points and the closed form, in plot coordinates.
struct Profile {
    /// (s, pN) of every quadrature point inside the drawn range.
    points: Vec<(f64, f64)>,
    /// (s, pN) of the loaded slave nodes.
    nodes: Vec<(f64, f64)>,
    /// Closed form: peak pressure and half-width (line) or radius (point).
    p0: f64,
    width: f64,
    /// Line contact: s is signed (−b..b); point contact: radial (0..a).
    signed: bool,
}

impl Profile {
    fn new(check: &HertzCheck, pair: &PairPoints, nodal: &NodalPressure) -> Self {
        let total = pair.force.iter().map(|f| f * f).sum::<f64>().sqrt();
        let (width, p0) = match check.kind {
            HertzKind::Line { thickness } => {
                hertz::hertz_line(total / thickness, check.radius, check.effective_modulus)
            }
            HertzKind::Point => hertz::hertz_point(total, check.radius, check.effective_modulus),
        };
        let signed = matches!(check.kind, HertzKind::Line { .. });
        let centre = active_centroid(pair);
        // Points well outside the contact zone only flatten the picture.
        let reach = 1.5 * width.max(farthest_active(pair, centre, signed));
        let points = pair
            .points
            .iter()
            .zip(&pair.pressure)
            .map(|(x, &p)| (coordinate(x, centre, signed), p))
            .filter(|(s, _)| s.abs() <= reach)
            .collect();
        let node_centre = centroid(nodal.points.iter());
        let nodes = nodal
            .points
            .iter()
            .zip(&nodal.pressure)
            .map(|(x, &p)| (coordinate(x, node_centre, signed), p))
            .collect();
        Profile {
            points,
            nodes,
            p0,
            width,
            signed,
        }
    }

    /// The closed form sampled across the contact zone (zero outside).
    fn closed_form(&self) -> Vec<(f64, f64)> {
        const N: usize = 400;
        let (lo, hi) = self.x_range();
        (0..=N)
            .map(|i| {
                let s = lo + (hi - lo) * i as f64 / N as f64;
                let q = 1.0 - (s / self.width).powi(2);
                (s, self.p0 * q.max(0.0).sqrt())
            })
            .collect()
    }

    fn x_range(&self) -> (f64, f64) {
        let far = self
            .points
            .iter()
            .map(|(s, _)| s.abs())
            .fold(1.2 * self.width, f64::max);
        if self.signed {
            (-far, far)
        } else {
            (0.0, far)
        }
    }

    fn y_max(&self) -> f64 {
        let top = self
            .points
            .iter()
            .chain(&self.nodes)
            .map(|(_, p)| *p)
            .fold(self.p0, f64::max);
        // Head room for the legend above the profile.
        if top > 0.0 {
            1.3 * top
        } else {
            1.0
        }
    }
}

/// Centroid (x, y) of the points carrying pressure: the centre of the contact
/// zone, wherever the bodies met. The origin when nothing is in contact.
fn active_centroid(pair: &PairPoints) -> [f64; 2] {
    centroid(
        (0..pair.points.len())
            .filter(|&i| pair.is_active(i))
            .map(|i| &pair.points[i]),
    )
}

/// Mean (x, y) of some points; the origin for none.
fn centroid<'a>(points: impl Iterator<Item = &'a [f64; 3]>) -> [f64; 2] {
    let active: Vec<&[f64; 3]> = points.collect();
    if active.is_empty() {
        return [0.0; 2];
    }
    let n = active.len() as f64;
    [
        active.iter().map(|x| x[0]).sum::<f64>() / n,
        active.iter().map(|x| x[1]).sum::<f64>() / n,
    ]
}

/// Line contact: x − x̄ (the cylinder's axis is along y); point contact:
/// the distance from the centre in the x–y plane.
fn coordinate(x: &[f64; 3], centre: [f64; 2], signed: bool) -> f64 {
    let dx = x[0] - centre[0];
    if signed {
        dx
    } else {
        dx.hypot(x[1] - centre[1])
    }
}

fn farthest_active(pair: &PairPoints, centre: [f64; 2], signed: bool) -> f64 {
    (0..pair.points.len())
        .filter(|&i| pair.is_active(i))
        .map(|i| coordinate(&pair.points[i], centre, signed).abs())
        .fold(0.0, f64::max)
}

/// Registers the font with plotters (its ab_glyph backend has no system
/// font lookup). Err says why there is none.
fn load_font() -> Result<(), String> {
    let path = std::env::var_os("CONTACTLINK_FONT")
        .map(PathBuf::from)
        .unwrap_or_else(|| PathBuf::from(DEFAULT_FONT));
    let bytes = std::fs::read(&path).map_err(|e| {
        format!(
            "no font at {} ({e}; install fonts-dejavu-core or set CONTACTLINK_FONT)",
            path.display()
        )
    })?;
    // plotters keeps fonts for the whole process; this runs once per process.
    let bytes: &'static [u8] = Box::leak(bytes.into_boxed_slice());
    plotters::style::register_font("sans-serif", FontStyle::Normal, bytes)
        .map_err(|_| format!("{} is not a usable TrueType font", path.display()))
}

fn title(check: &HertzCheck, profile: &Profile, cmp: Option<&hertz::HertzComparison>) -> String {
    let w = if profile.signed { "b" } else { "a" };
    let kind = if profile.signed { "line" } else { "point" };
    match cmp {
        Some(c) => format!(
            "Hertz {kind} contact '{}': p0 {:.4} ({:+.2} %), {w} {:.4} ({:+.2} %)",
            check.pair,
            c.p0,
            100.0 * c.p0_error(),
            c.width,
            100.0 * c.width_error()
        ),
        None => format!(
            "Hertz {kind} contact '{}': p0 {:.4}, {w} {:.4} (closed form; too few loaded nodes to fit)",
            check.pair, profile.p0, profile.width
        ),
    }
}

fn draw(
    output: &Path,
    check: &HertzCheck,
    profile: &Profile,
    cmp: Option<&hertz::HertzComparison>,
    with_text: bool,
) -> Result<(), Box<dyn std::error::Error>> {
    let root = BitMapBackend::new(output, (1000, 650)).into_drawing_area();
    root.fill(&WHITE)?;
    let (lo, hi) = profile.x_range();
    let mut builder = ChartBuilder::on(&root);
    builder.margin(20);
    if with_text {
        builder
            .caption(title(check, profile, cmp), ("sans-serif", 20))
            .x_label_area_size(45)
            .y_label_area_size(70);
    }
    let mut chart = builder.build_cartesian_2d(lo..hi, 0.0..profile.y_max())?;
    let mut mesh = chart.configure_mesh();
    if with_text {
        let x_desc = if profile.signed {
            "x − x_c (x_c: centre of the contact zone)"
        } else {
            "r (distance from the contact centre in the x–y plane)"
        };
        mesh.x_desc(x_desc).y_desc("contact pressure").draw()?;
    } else {
        // Tick labels are text too: grid lines only.
        mesh.x_labels(0).y_labels(0).draw()?;
    }
    let red = RGBColor(200, 30, 30);
    let blue = RGBColor(30, 80, 200);
    // Labels are drawn as text in the legend: only with a font.
    let curve = chart.draw_series(LineSeries::new(profile.closed_form(), red.stroke_width(2)))?;
    if with_text {
        curve
            .label("closed form p0·√(1 − (s/w)²), load from the contact force")
            .legend(move |(x, y)| PathElement::new(vec![(x, y), (x + 20, y)], red));
    }
    let points = chart.draw_series(
        profile
            .points
            .iter()
            .map(|&(s, p)| Circle::new((s, p), 3, blue.filled())),
    )?;
    if with_text {
        points
            .label("computed pressure λN at the slave quadrature points")
            .legend(move |(x, y)| Circle::new((x + 10, y), 3, blue.filled()));
    }
    let green = RGBColor(20, 140, 60);
    let nodes = chart.draw_series(
        profile
            .nodes
            .iter()
            .map(|&(s, p)| TriangleMarker::new((s, p), 5, green.filled())),
    )?;
    if with_text {
        nodes
            .label("computed nodal pressure (what the p0, b fit uses)")
            .legend(move |(x, y)| TriangleMarker::new((x + 10, y), 5, green.filled()));
        chart
            .configure_series_labels()
            .background_style(WHITE.mix(0.8))
            .border_style(BLACK)
            .position(SeriesLabelPosition::UpperRight)
            .draw()?;
    }
    root.present()?;
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::*;

    fn pair(points: Vec<[f64; 3]>, pressure: Vec<f64>) -> PairPoints {
        PairPoints {
            points,
            pressure,
            weight: None,
            force: [0.0, 0.0, 10.0],
            active_nodes: None,
            friction: None,
        }
    }

    #[test]
    fn line_coordinate_is_relative_to_the_active_centroid() {
        let p = pair(
            vec![[1.0, 0.0, 0.0], [3.0, 0.0, 0.0], [9.0, 0.0, 0.0]],
            vec![1.0, 1.0, 0.0],
        );
        let c = active_centroid(&p);
        assert_eq!(c, [2.0, 0.0]);
        assert_eq!(coordinate(&p.points[0], c, true), -1.0);
        assert_eq!(coordinate(&[2.0, 4.0, 0.0], [-1.0, 0.0], false), 5.0);
    }

    #[test]
    fn closed_form_peaks_at_the_centre_and_vanishes_outside() {
        let prof = Profile {
            points: vec![],
            nodes: vec![],
            p0: 2.0,
            width: 1.0,
            signed: true,
        };
        let c = prof.closed_form();
        let peak = c.iter().map(|(_, p)| *p).fold(0.0, f64::max);
        assert!((peak - 2.0).abs() < 1e-3);
        assert!(c
            .iter()
            .filter(|(s, _)| s.abs() > 1.0)
            .all(|(_, p)| *p == 0.0));
    }
}
