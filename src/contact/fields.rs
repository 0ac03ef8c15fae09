//! What a pair hands the result file after a converged step, and what it
//! reads back from one to continue a run: named fields whose rows are this
//! rank's slave points or its owned mesh nodes. Each formulation decides
//! which fields it writes (those that mean something for it) and which it
//! reads on a restart; the writer and the reader handle any field alike.
//! The dataset names are spelled here once (the result file's other names
//! are in `output::layout`, which re-exports these).
use super::outcome::PairForce;

/// Members of a pair group `/steps/<NNNNNN>/contact/<pair>/`: per-point
/// arrays (rows: the pair's slave quadrature points, facet-major in the
/// order of the slave set)...
pub const PAIR_POINTS: &str = "points";
pub const PAIR_PRESSURE: &str = "pressure";
pub const PAIR_GAP: &str = "gap";
pub const PAIR_LAMBDA_N: &str = "lambda_n";
pub const PAIR_WEIGHT: &str = "weight";
/// ...with friction (the links)...
pub const PAIR_TRACTION_T: &str = "traction_t";
pub const PAIR_SLIP: &str = "slip";
pub const PAIR_STATE: &str = "state";
pub const PAIR_LAMBDA_T: &str = "lambda_t";
pub const PAIR_SLIP_ORIGIN: &str = "slip_origin";
pub const PAIR_HISTORY_IDS: &str = "history_ids";
/// ...nodal fields (rows: mesh nodes, zero off the pair's slave surface;
/// the mortar)...
pub const PAIR_NODE_LAMBDA: &str = "node_lambda";
pub const PAIR_NODE_WEIGHTED_GAP: &str = "node_weighted_gap";
pub const PAIR_NODE_AREA: &str = "node_area";
pub const PAIR_NODE_TRACTION: &str = "node_traction";
/// A frictional mortar pair's nodal state (0 open, 1 stick, 2 slip) and
/// the mean tangential slip of the step at each slave node.
pub const PAIR_NODE_STATE: &str = "node_state";
pub const PAIR_NODE_SLIP: &str = "node_slip";
/// A frictional mortar pair's history for `--restart` (N,3): λT_j, and
/// where the next step measures slip from (the pair nodes' positions).
pub const PAIR_NODE_LAMBDA_T: &str = "node_lambda_t";
pub const PAIR_NODE_SLIP_ORIGIN: &str = "node_slip_origin";
/// ...and the pair's totals, `(3,)` and `(1,)`.
pub const PAIR_FORCE: &str = "force";
pub const PAIR_PENALTY: &str = "penalty";

/// A contact state as a number (`state`, `node_state`).
pub const OPEN: f64 = 0.0;
pub const STICK: f64 = 1.0;
pub const SLIP: f64 = 2.0;

/// One named field: `cols` values per row, rows in the order of the space
/// it belongs to.
#[derive(Debug, Clone, PartialEq)]
pub struct Field {
    pub name: &'static str,
    pub cols: usize,
    pub values: Vec<f64>,
}

impl Field {
    pub fn scalar(name: &'static str, values: Vec<f64>) -> Self {
        Field {
            name,
            cols: 1,
            values,
        }
    }

    pub fn vector(name: &'static str, values: &[[f64; 3]]) -> Self {
        Field {
            name,
            cols: 3,
            values: values.iter().flatten().copied().collect(),
        }
    }
}

/// A pair's output at a converged step, this rank's rows. Which fields a
/// pair writes depends on the pair alone (its formulation and friction),
/// never on this rank's rows: every rank writes the same datasets.
#[derive(Debug, Clone, Default)]
pub struct PairOutput {
    /// Rows: this rank's slave points, in the pair's point order
    /// (`SlaveSurface::global_point` numbers them).
    pub point_fields: Vec<Field>,
    /// Rows: this rank's owned mesh nodes (zero off the pair).
    pub node_fields: Vec<Field>,
    /// This rank's part of the contact force on the slave surface.
    pub force: PairForce,
    /// Owned slave nodes: reference position and nodal contact pressure
    /// (what the Hertz comparison fits).
    pub nodes: Vec<([f64; 3], f64)>,
}

impl PairOutput {
    /// The point field `name` (empty if the pair does not write it).
    pub fn point_field(&self, name: &str) -> &[f64] {
        self.point_fields
            .iter()
            .find(|f| f.name == name)
            .map_or(&[], |f| &f.values)
    }
}

/// Whose rows a restart field has.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum RowSpace {
    /// The pair's slave points (the dataset's own row count; the first
    /// such field read fixes it for the rest).
    Points,
    /// Mesh nodes.
    Nodes,
}

/// One field a restart reads: its dataset, width, row space, and the rows
/// this rank needs.
#[derive(Debug, Clone)]
pub struct RestartField {
    pub name: &'static str,
    pub cols: usize,
    pub space: RowSpace,
    pub rows: Vec<usize>,
}

/// What a pair reads back from a result file to continue from its step.
#[derive(Debug, Clone, Default)]
pub struct RestartRequest {
    pub fields: Vec<RestartField>,
}

/// The rows a restart read for one pair: each requested field's values in
/// the order of its request (a row the file lacks arrives as NaN), the
/// pair's penalty at that step (None in files that lack it) and the step's
/// load factor.
#[derive(Debug, Clone, Default)]
pub struct RestartRows {
    pub penalty: Option<f64>,
    pub load_factor: f64,
    pub fields: Vec<Vec<f64>>,
}

impl RestartRows {
    /// The values of the `i`-th requested field.
    pub fn field(&self, i: usize) -> &[f64] {
        self.fields.get(i).map_or(&[], Vec::as_slice)
    }

    /// The `i`-th field as 3-vectors.
    pub fn triples(&self, i: usize) -> Vec<[f64; 3]> {
        self.field(i)
            .chunks_exact(3)
            .map(|c| [c[0], c[1], c[2]])
            .collect()
    }
}
