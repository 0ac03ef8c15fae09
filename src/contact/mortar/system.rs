//! Nodal assembly of the mortar normal contact: weighted gaps, nodal
//! pressures, residual and consistent tangent of a set of segments.
//!
//! Sign and scaling. Each slave node `j` carries a nominal pressure `λ_j`
//! (force per reference area: the integrals are over the reference slave
//! surface, see `segment_terms`). With `A_j = ∫ N_j dA₀` its reference nodal
//! area, `ḡ_j = g̃_j / A_j` is the node's mean gap and the pressure of the
//! converged Newton solution is `p_j = ⟨λ_j − ε_j ḡ_j⟩` (the links' own rule,
//! [`contact_pressure`]). The residual, added to `R = f_int − f_ext`, is
//! the mortar force `r = −Σ_j p_j c_j` with `c_j = ∂g̃_j/∂x` at fixed `D`,
//! `M` and `ν`: `+p_j D_jk ν` on slave node `k`, `−p_j M_jl ν` on master node
//! `l` (for a uniform `p` these are the exact consistent nodal forces on
//! both sides, hence the patch test). Its tangent, exact for this residual,
//! is `Σ_j p_j ∂c_j/∂x + c_j ⊗ ∂p_j/∂x` with `∂p_j/∂x = −(ε_j/A_j) ∂g̃_j/∂x`
//! on a closed node, `∂g̃_j/∂x` including the move of the auxiliary plane, of
//! the clipped polygon and of the dual basis. It couples every DOF of every
//! segment of node `j` with every other: see [`node_supports`].
use super::coverage;
use super::segment::{dual_coefficients, nodal_areas, segment_terms, MortarRules, SegmentTerms};
use super::MAX_FACET_NODES;
use crate::contact::autodiff::{Dual, Scalar, Seed, Vec3};
use crate::contact::penalty::contact_pressure;
use crate::fem::FacetType;

/// Variables of one segment: slave nodes at `3a + i`, master nodes at
/// `12 + 3b + i` (fixed slots, whatever the facet types).
pub const SEGMENT_DOFS: usize = 6 * MAX_FACET_NODES;
pub(super) const MASTER_OFFSET: usize = 3 * MAX_FACET_NODES;
type D = Dual<SEGMENT_DOFS>;

/// A node DOF: (node id, component).
pub type NodeDof = (u32, usize);

/// The geometry of a mortar interface as node ids into `positions`.
#[derive(Debug, Clone, Copy)]
pub struct Interface<'a> {
    pub slave_type: FacetType,
    pub master_type: FacetType,
    /// Current position of every node id used below.
    pub positions: &'a [[f64; 3]],
    /// Reference position of every node id (slave nodes are used).
    pub reference: &'a [[f64; 3]],
    pub slave_facets: &'a [[u32; MAX_FACET_NODES]],
    pub master_facets: &'a [[u32; MAX_FACET_NODES]],
    /// Slave–master facet pairs that may overlap (from a search).
    pub candidates: &'a [(u32, u32)],
    /// Per slave facet: whether its forces are assembled here (a rank
    /// evaluates a layer of other ranks' facets too, so that the weighted gap
    /// of each node of its own facets is complete).
    pub assembled: &'a [bool],
}

/// Per slave node: its multiplier, penalty and reference nodal area.
#[derive(Debug, Clone, Default)]
pub struct NodalData {
    /// Slave node ids; `slot_of` maps a node id to its position here.
    pub nodes: Vec<u32>,
    pub lambda: Vec<f64>,
    pub penalty: Vec<f64>,
    pub area: Vec<f64>,
    slot: std::collections::HashMap<u32, usize>,
    /// The f64 segments of the last evaluation (see [`SegmentCache`]).
    pub cache: SegmentCache,
}

/// The f64 segments of the last positions they were integrated at. Newton
/// asks for the residual and then the tangent at the same iterate, and the
/// Uzawa update follows the last residual: the tangent's node states and
/// the update reuse the residual's segments instead of clipping and
/// integrating them again. Keyed by the positions and the candidates (all
/// else an interface holds is fixed for a pair); a clone starts empty.
#[derive(Default)]
pub struct SegmentCache(std::sync::Mutex<Option<CachedSegments>>);

struct CachedSegments {
    positions: Vec<[f64; 3]>,
    candidates: Vec<(u32, u32)>,
    segments: Vec<Segment<f64>>,
    covered: Vec<bool>,
}

impl SegmentCache {
    /// [`covered_segments`] in f64 of the interface, from the cache when
    /// its positions and candidates are those of the last call.
    pub fn segments(
        &self,
        interface: &Interface,
        rules: &MortarRules,
    ) -> (Vec<Segment<f64>>, Vec<bool>) {
        let mut last = self.0.lock().unwrap_or_else(|e| e.into_inner());
        if let Some(c) = last
            .as_ref()
            .filter(|c| c.positions == interface.positions && c.candidates == interface.candidates)
        {
            return (c.segments.clone(), c.covered.clone());
        }
        let (segments, covered) = covered_segments::<f64>(interface, rules);
        *last = Some(CachedSegments {
            positions: interface.positions.to_vec(),
            candidates: interface.candidates.to_vec(),
            segments: segments.clone(),
            covered: covered.clone(),
        });
        (segments, covered)
    }
}

impl Clone for SegmentCache {
    fn clone(&self) -> Self {
        SegmentCache::default()
    }
}

impl std::fmt::Debug for SegmentCache {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.write_str("SegmentCache")
    }
}

impl NodalData {
    pub fn new(nodes: Vec<u32>, lambda: Vec<f64>, penalty: Vec<f64>, area: Vec<f64>) -> Self {
        let slot = nodes.iter().enumerate().map(|(i, &n)| (n, i)).collect();
        NodalData {
            nodes,
            lambda,
            penalty,
            area,
            slot,
            cache: SegmentCache::default(),
        }
    }

    pub fn slot_of(&self, node: u32) -> Option<usize> {
        self.slot.get(&node).copied()
    }
}

/// One segment's integrals, with the facets it came from.
#[derive(Debug, Clone, Copy)]
pub struct Segment<T> {
    pub slave: u32,
    pub master: u32,
    pub terms: SegmentTerms<T>,
}

fn seeded<T: Seed>(
    interface: &Interface,
    nodes: &[u32],
    offset: usize,
) -> [Vec3<T>; MAX_FACET_NODES] {
    let mut out = [[T::from_f64(0.0); 3]; MAX_FACET_NODES];
    for (a, (o, &n)) in out.iter_mut().zip(nodes).enumerate() {
        let p = interface.positions[n as usize];
        let base = offset + 3 * a;
        *o = [
            T::seed(p[0], base),
            T::seed(p[1], base + 1),
            T::seed(p[2], base + 2),
        ];
    }
    out
}

/// Every overlapping candidate's integrals, with the `D` of covered facets
/// set to their diagonal ([`coverage`](super::coverage)).
pub fn segments<T: Seed>(interface: &Interface, rules: &MortarRules) -> Vec<Segment<T>> {
    covered_segments(interface, rules).0
}

/// [`segments`] and, per slave facet, whether they cover it whole
/// ([`covered_facets`]).
pub fn covered_segments<T: Seed>(
    interface: &Interface,
    rules: &MortarRules,
) -> (Vec<Segment<T>>, Vec<bool>) {
    let mut out = Vec::with_capacity(interface.candidates.len());
    for_each_segment(interface, rules, &[], |seg| out.push(seg));
    let covered = covered_facets(interface, rules, &out);
    coverage::set_diagonals(
        &covered,
        out.iter_mut().map(|s| (s.slave, &mut s.terms)),
        |f| slave_nodal_areas(interface, f, rules),
        interface.slave_type.nodes(),
    );
    (out, covered)
}

/// Per slave facet: whether the `segments` (in candidate order) cover it
/// whole ([`coverage::covered_facets`]).
pub fn covered_facets<T: Scalar>(
    interface: &Interface,
    rules: &MortarRules,
    segments: &[Segment<T>],
) -> Vec<bool> {
    coverage::covered_facets(
        interface.slave_facets.len(),
        segments.iter().map(|s| (s.slave, s.terms.area.re())),
        |f| slave_nodal_areas(interface, f, rules).iter().sum(),
    )
}

/// `∫ N_j dA₀` of slave facet `f` (reference positions, the dual basis' rule).
pub(super) fn slave_nodal_areas(
    interface: &Interface,
    f: u32,
    rules: &MortarRules,
) -> [f64; MAX_FACET_NODES] {
    let ns = interface.slave_type.nodes();
    let mut x_ref = [[0.0; 3]; MAX_FACET_NODES];
    for (r, &n) in x_ref
        .iter_mut()
        .zip(&interface.slave_facets[f as usize][..ns])
    {
        *r = interface.reference[n as usize];
    }
    nodal_areas(interface.slave_type, &x_ref[..ns], rules)
}

/// Calls `visit` with every overlapping candidate's integrals, in candidate
/// order. The tangent streams its `Dual` segments through here: 8 KB each,
/// a vector of them was grown, copied and paged in at every Newton
/// iteration (a fifth of a frictional mortar run). `covered` (per slave
/// facet, or empty) are the facets [`covered_facets`] found on these
/// candidates' values: their `D` is set, not integrated.
pub fn for_each_segment<T: Seed>(
    interface: &Interface,
    rules: &MortarRules,
    covered: &[bool],
    mut visit: impl FnMut(Segment<T>),
) {
    let (ns, nm) = (interface.slave_type.nodes(), interface.master_type.nodes());
    let mut cached: Option<(u32, [[f64; MAX_FACET_NODES]; MAX_FACET_NODES])> = None;
    let mut last_covered = None;
    const NO_D: [f64; MAX_FACET_NODES] = [0.0; MAX_FACET_NODES];
    for &(s, m) in interface.candidates {
        let snodes = &interface.slave_facets[s as usize][..ns];
        let mnodes = &interface.master_facets[m as usize][..nm];
        let xs = seeded::<T>(interface, snodes, 0);
        let xm = seeded::<T>(interface, mnodes, MASTER_OFFSET);
        let mut x_ref = [[0.0; 3]; MAX_FACET_NODES];
        for (r, &n) in x_ref.iter_mut().zip(snodes) {
            *r = interface.reference[n as usize];
        }
        // The dual basis is the reference facet's (constant): compute it once
        // per slave facet, for its consecutive candidates.
        let a = match cached {
            Some((f, a)) if f == s => a,
            _ => match dual_coefficients::<f64>(interface.slave_type, &x_ref[..ns], rules) {
                Some(a) => {
                    cached = Some((s, a));
                    a
                }
                None => continue,
            },
        };
        // A covered facet's diagonal goes on its first segment.
        let diagonal = match covered.get(s as usize) {
            Some(true) if last_covered != Some(s) => {
                Some(nodal_areas(interface.slave_type, &x_ref[..ns], rules))
            }
            Some(true) => Some(NO_D),
            _ => None,
        };
        let terms = segment_terms(
            interface.slave_type,
            &xs[..ns],
            &x_ref[..ns],
            interface.master_type,
            &xm[..nm],
            &a,
            rules,
            diagonal.as_ref(),
        );
        if let Some(terms) = terms {
            if diagonal.is_some() {
                last_covered = Some(s);
            }
            visit(Segment {
                slave: s,
                master: m,
                terms,
            });
        }
    }
}

/// Nodal weighted gaps `g̃_j` (by slot) and whether the segments cover the
/// node: `∫ Φ_j dA` over them (the row sum of `D`, `A_j` when the node's
/// facets are covered) at least half of `A_j`. Φ_j changes sign inside a
/// facet, so over a small part of its support `∫ Φ_j g` may be negative
/// with `g > 0` everywhere: such a node would be pulled into a contact it
/// does not have.
pub fn weighted_gaps<T: Scalar>(
    interface: &Interface,
    nodal: &NodalData,
    segments: &[Segment<T>],
) -> (Vec<f64>, Vec<bool>) {
    let mut gap = vec![0.0; nodal.nodes.len()];
    let mut weight = vec![0.0; nodal.nodes.len()];
    let ns = interface.slave_type.nodes();
    for seg in segments {
        for (a, &node) in interface.slave_facets[seg.slave as usize][..ns]
            .iter()
            .enumerate()
        {
            if let Some(j) = nodal.slot_of(node) {
                gap[j] += seg.terms.weighted_gap[a].re();
                weight[j] += seg.terms.d[a][..ns].iter().map(Scalar::re).sum::<f64>();
            }
        }
    }
    let covered = weight
        .iter()
        .zip(&nodal.area)
        .map(|(w, a)| *w >= 0.5 * a)
        .collect();
    (gap, covered)
}

/// The state of one slave node after an evaluation.
#[derive(Debug, Clone, Copy, Default, PartialEq)]
pub struct NodeState {
    /// `g̃_j` (length × area).
    pub weighted_gap: f64,
    /// `p_j = ⟨λ_j − ε_j g̃_j / A_j⟩`.
    pub pressure: f64,
    /// In contact (covered and `λ_j − ε_j ḡ_j ≥ 0`): contributes a tangent.
    pub closed: bool,
}

pub fn node_states(nodal: &NodalData, gap: &[f64], covered: &[bool]) -> Vec<NodeState> {
    (0..nodal.nodes.len())
        .map(|j| {
            let mean = gap[j] / nodal.area[j];
            let trial = nodal.lambda[j] - nodal.penalty[j] * mean;
            NodeState {
                weighted_gap: gap[j],
                pressure: if covered[j] {
                    contact_pressure(nodal.lambda[j], nodal.penalty[j], mean)
                } else {
                    0.0
                },
                closed: covered[j] && trial >= 0.0,
            }
        })
        .collect()
}

/// Node ids of a segment's variables in slot order (`u32::MAX`: unused).
pub(super) fn segment_nodes(
    interface: &Interface,
    seg_slave: u32,
    seg_master: u32,
) -> [u32; 2 * MAX_FACET_NODES] {
    let mut ids = [u32::MAX; 2 * MAX_FACET_NODES];
    let (ns, nm) = (interface.slave_type.nodes(), interface.master_type.nodes());
    ids[..ns].copy_from_slice(&interface.slave_facets[seg_slave as usize][..ns]);
    ids[MAX_FACET_NODES..MAX_FACET_NODES + nm]
        .copy_from_slice(&interface.master_facets[seg_master as usize][..nm]);
    ids
}

/// The coefficient of node `a`'s pressure in the force on segment variable
/// `v = 3 b + i` (`b < 4` slave node, else master node `b − 4`).
pub(super) fn force_coefficient<T: Scalar>(terms: &SegmentTerms<T>, a: usize, v: usize) -> T {
    let (b, i) = (v / 3, v % 3);
    if b < MAX_FACET_NODES {
        terms.d[a][b] * terms.normal[i]
    } else {
        -(terms.m[a][b - MAX_FACET_NODES] * terms.normal[i])
    }
}

/// Calls `visit(segment, a, j, ids)` for every assembled segment and each of
/// its slave facet's nodes `a` that carries a nodal slot `j`; `ids` are the
/// segment's node ids (`u32::MAX` where a position is unused). The normal and
/// the tangential residuals walk the segments this one way.
pub(super) fn for_each_slave_node<T: Scalar>(
    interface: &Interface,
    nodal: &NodalData,
    segments: &[Segment<T>],
    mut visit: impl FnMut(&Segment<T>, usize, usize, &[u32]),
) {
    let ns = interface.slave_type.nodes();
    for seg in segments
        .iter()
        .filter(|s| interface.assembled[s.slave as usize])
    {
        let ids = segment_nodes(interface, seg.slave, seg.master);
        for (a, &node) in interface.slave_facets[seg.slave as usize][..ns]
            .iter()
            .enumerate()
        {
            if let Some(j) = nodal.slot_of(node) {
                visit(seg, a, j, &ids);
            }
        }
    }
}

/// Adds the residual of the assembled segments: `emit(node, component, value)`.
pub fn residual<T: Scalar>(
    interface: &Interface,
    nodal: &NodalData,
    segments: &[Segment<T>],
    states: &[NodeState],
    mut emit: impl FnMut(u32, usize, f64),
) {
    for_each_slave_node(interface, nodal, segments, |seg, a, j, ids| {
        let p = states[j].pressure;
        if p == 0.0 {
            return;
        }
        for v in 0..SEGMENT_DOFS {
            if ids[v / 3] != u32::MAX {
                emit(
                    ids[v / 3],
                    v % 3,
                    p * force_coefficient(&seg.terms, a, v).re(),
                );
            }
        }
    });
}

/// Merges sparse vectors over node DOFs (sorted, duplicates summed) through
/// a dense scatter reused across the nodes of one tangent: a stable sort of
/// every list took 5 % of a frictional mortar run. Each sum starts from its
/// first entry and adds the others in emission order, as the sort-and-sum
/// did, so the result is the same bit for bit.
pub(super) struct Merger {
    sum: Vec<f64>,
    seen: Vec<bool>,
    touched: Vec<usize>,
}

impl Merger {
    pub(super) fn new() -> Self {
        Merger {
            sum: Vec::new(),
            seen: Vec::new(),
            touched: Vec::new(),
        }
    }

    /// `v` merged, sorted by (node, component).
    pub(super) fn merged(&mut self, v: &[(NodeDof, f64)]) -> Vec<(NodeDof, f64)> {
        // Components are < 3, so `3 id + c` orders as (id, c).
        let key = |k: NodeDof| 3 * k.0 as usize + k.1;
        self.touched.clear();
        for &(k, x) in v {
            let p = key(k);
            if p >= self.sum.len() {
                self.sum.resize(p + 1, 0.0);
                self.seen.resize(p + 1, false);
            }
            if self.seen[p] {
                self.sum[p] += x;
            } else {
                self.seen[p] = true;
                self.sum[p] = x;
                self.touched.push(p);
            }
        }
        self.touched.sort_unstable();
        let mut out = Vec::with_capacity(self.touched.len());
        for &p in &self.touched {
            self.seen[p] = false;
            out.push((((p / 3) as u32, p % 3), self.sum[p]));
        }
        out
    }
}

/// Adds the tangent of the assembled segments: `emit(row, col, value)`.
/// `segments` must hold every segment of every node of an assembled facet.
pub fn tangent(
    interface: &Interface,
    nodal: &NodalData,
    segments: &[Segment<D>],
    states: &[NodeState],
    mut emit: impl FnMut(NodeDof, NodeDof, f64),
) {
    let mut t = FrictionlessTangent::new(interface, nodal, states);
    for seg in segments {
        t.add(seg, &mut emit);
    }
    t.finish(emit);
}

/// The tangent of a frictionless pair, one segment at a time: a segment's
/// own terms are emitted as one block, the per-node outer products once
/// every segment has been added (as `friction::FrictionalTangent`).
pub struct FrictionlessTangent<'a> {
    interface: &'a Interface<'a>,
    nodal: &'a NodalData,
    states: &'a [NodeState],
    normal: NormalTangent,
    local: Block,
}

impl<'a> FrictionlessTangent<'a> {
    pub fn new(
        interface: &'a Interface<'a>,
        nodal: &'a NodalData,
        states: &'a [NodeState],
    ) -> Self {
        FrictionlessTangent {
            interface,
            nodal,
            states,
            normal: NormalTangent::new(nodal),
            local: [[0.0; SEGMENT_DOFS]; SEGMENT_DOFS],
        }
    }

    pub fn add(&mut self, seg: &Segment<D>, emit: impl FnMut(NodeDof, NodeDof, f64)) {
        let (interface, nodal) = (self.interface, self.nodal);
        if self
            .normal
            .add(interface, nodal, seg, self.states, &mut self.local)
        {
            let ids = segment_nodes(interface, seg.slave, seg.master);
            emit_local(&ids, &mut self.local, emit);
        }
    }

    pub fn finish(self, emit: impl FnMut(NodeDof, NodeDof, f64)) {
        self.normal.finish(self.nodal, emit);
    }
}

/// A segment's dense block over its variables (`local[v][w]`).
pub(super) type Block = [[f64; SEGMENT_DOFS]; SEGMENT_DOFS];

/// The normal tangent, one segment at a time: the per-segment part goes
/// into a dense block the caller emits (the tangential part adds to the
/// same block), the per-node part is emitted once every segment has been
/// added (it must then hold every segment of every node of an assembled
/// facet).
pub struct NormalTangent {
    /// Per closed node: ∂g̃_j/∂x over all its segments, and the assembled
    /// force coefficients c_j (rows).
    pub(super) grad: Vec<Vec<(NodeDof, f64)>>,
    pub(super) rows: Vec<Vec<(NodeDof, f64)>>,
}

impl NormalTangent {
    pub fn new(nodal: &NodalData) -> Self {
        let nn = nodal.nodes.len();
        NormalTangent {
            grad: vec![Vec::new(); nn],
            rows: vec![Vec::new(); nn],
        }
    }

    /// Adds `seg`'s terms: Σ_j p_j ∂c_j/∂x into `local` (summed over the
    /// segment's nodes before it is emitted: a quarter of the entries a
    /// node-by-node emission made); true if it added any.
    pub fn add(
        &mut self,
        interface: &Interface,
        nodal: &NodalData,
        seg: &Segment<D>,
        states: &[NodeState],
        local: &mut Block,
    ) -> bool {
        let ns = interface.slave_type.nodes();
        let ids = segment_nodes(interface, seg.slave, seg.master);
        let assembled = interface.assembled[seg.slave as usize];
        let mut any = false;
        for (a, &node) in interface.slave_facets[seg.slave as usize][..ns]
            .iter()
            .enumerate()
        {
            let Some(j) = nodal.slot_of(node) else {
                continue;
            };
            if !states[j].closed {
                continue;
            }
            let p = states[j].pressure;
            // A covered facet's D is diagonal and on its first segment
            // alone (`covered_facets`): its zeros add nothing.
            let no_d: [bool; MAX_FACET_NODES] =
                std::array::from_fn(|b| seg.terms.d[a][b].is_zero());
            for v in 0..SEGMENT_DOFS {
                let id = ids[v / 3];
                if id == u32::MAX {
                    continue;
                }
                self.grad[j].push(((id, v % 3), seg.terms.weighted_gap[a].eps[v]));
                if !assembled || no_d.get(v / 3) == Some(&true) {
                    continue;
                }
                let c = force_coefficient(&seg.terms, a, v);
                self.rows[j].push(((id, v % 3), c.re));
                if p != 0.0 {
                    any = true;
                    for (l, d) in local[v].iter_mut().zip(&c.eps) {
                        *l += p * d;
                    }
                }
            }
        }
        any
    }

    /// c_j ⊗ ∂p_j/∂x with ∂p_j/∂x = −(ε_j/A_j) ∂g̃_j/∂x.
    pub fn finish(self, nodal: &NodalData, emit: impl FnMut(NodeDof, NodeDof, f64)) {
        emit_scaled_outer(nodal, -1.0, self.rows, self.grad, emit);
    }
}

/// Emits a segment's dense block `local[v][w]` (segment variables, node ids
/// `ids`) and clears it.
pub(super) fn emit_local(
    ids: &[u32; 2 * MAX_FACET_NODES],
    local: &mut Block,
    mut emit: impl FnMut(NodeDof, NodeDof, f64),
) {
    for (v, row) in local.iter_mut().enumerate() {
        let id = ids[v / 3];
        for (w, x) in row.iter_mut().enumerate() {
            let col = ids[w / 3];
            if id != u32::MAX && col != u32::MAX && *x != 0.0 {
                emit((id, v % 3), (col, w % 3), *x);
            }
            *x = 0.0;
        }
    }
}

/// Emits `sign (ε_j/A_j) r_j ⊗ g_j` for every node `j` with rows: `rows[j]`
/// and `cols[j]` are unmerged (dof, value) lists, merged here. The normal
/// tangents (deformable and rigid masters, and the main part) end this way.
pub(super) fn emit_scaled_outer(
    nodal: &NodalData,
    sign: f64,
    mut rows: Vec<Vec<(NodeDof, f64)>>,
    mut cols: Vec<Vec<(NodeDof, f64)>>,
    mut emit: impl FnMut(NodeDof, NodeDof, f64),
) {
    let mut merger = Merger::new();
    for j in 0..rows.len() {
        if rows[j].is_empty() {
            continue;
        }
        let scale = sign * nodal.penalty[j] / nodal.area[j];
        let g = merger.merged(&std::mem::take(&mut cols[j]));
        for (row, c) in merger.merged(&std::mem::take(&mut rows[j])) {
            for (col, dg) in &g {
                let v = c * dg * scale;
                if v != 0.0 {
                    emit(row, *col, v);
                }
            }
        }
    }
}

/// For every slave node: the node ids its tangent couples (all nodes of all
/// its segments), sorted. The Jacobian pattern needs `S_j × S_j` for each
/// `j` (the segments of an evaluation, f64 suffices).
pub fn node_supports<T: Scalar>(
    interface: &Interface,
    nodal: &NodalData,
    segments: &[Segment<T>],
) -> Vec<Vec<u32>> {
    let ns = interface.slave_type.nodes();
    let mut support: Vec<Vec<u32>> = vec![Vec::new(); nodal.nodes.len()];
    for seg in segments {
        let ids = segment_nodes(interface, seg.slave, seg.master);
        for &node in &interface.slave_facets[seg.slave as usize][..ns] {
            if let Some(j) = nodal.slot_of(node) {
                support[j].extend(ids.iter().filter(|&&n| n != u32::MAX));
            }
        }
    }
    for s in &mut support {
        s.sort_unstable();
        s.dedup();
    }
    support
}
