//! Coulomb friction on the nodal mortar multipliers (docs/formulation.md
//! §13.3): the weighted tangential slip of a slave node, the links' return
//! map on its tangential multiplier, and the residual and exact tangent of
//! the tangential forces.
//!
//! Per slave node `j`, over the segments of its facets:
//! - weighted slip `ũ_j = Σ_k D_jk Δ¹_k − Σ_l M_jl Δ²_l`, with `Δ` the nodes'
//!   increment of the step (`x − xₙ` quasi-static, `Δt v(x)` in dynamics,
//!   both affine in `x`: [`Increment`]), i.e. the relative motion of the
//!   material points in contact now, weighted with `Φ_j`;
//! - node normal `n_j = a_j / |a_j|`, `a_j = Σ_s A_s ν_s` (segment areas and
//!   auxiliary-plane normals);
//! - trial `t*_j = P_j λT_j + εT P_j ũ_j / A_j` (`P_j = I − n_j ⊗ n_j`,
//!   `A_j` the reference nodal area, so `ũ_j / A_j` is the mean slip), then
//!   stick `tT_j = t*_j` if `|t*_j| ≤ μ p_j`, else `tT_j = μ p_j t*_j/|t*_j|`
//!   with `p_j = λ_j − ε_j g̃_j / A_j` of the closed node;
//! - residual `+D_jk tT_j` on slave node `k`, `−M_jl tT_j` on master node
//!   `l` (the variation of `ũ_j` at fixed `D`, `M`, as the normal part).
//!
//! `tT_j` is a function of seven node aggregates (`g̃_j`, `a_j`, `ũ_j`),
//! each a sum of segment terms. The law is evaluated once per node in
//! `Dual<7>` over those aggregates, and the chain rule through the
//! segments' `Dual<24>` gives `∂tT_j/∂x`: the slip branch, the coupling to
//! `p_j` and, in dynamics, the damping `Δt ∂v/∂x` all land in the tangent.
use super::system::{
    emit_local, for_each_slave_node, segment_nodes, Block, Interface, Merger, NodalData, NodeDof,
    NodeState, NormalTangent, Segment, SEGMENT_DOFS,
};
use super::MAX_FACET_NODES;
use crate::contact::autodiff::{self, Dual, Scalar, Seed, Vec3};

type D = Dual<{ super::system::SEGMENT_DOFS }>;
/// The node aggregates the law depends on: `g̃`, `a` (3), `ũ` (3).
const AGGREGATES: usize = 7;

/// The friction data of the slave nodes (by slot, as [`NodalData`]).
#[derive(Debug, Clone, Default)]
pub struct NodalFriction {
    pub mu: f64,
    /// εT per slot.
    pub penalty: Vec<f64>,
    /// λT per slot (a vector, the sense of `tT`: along the slave's slip).
    pub lambda: Vec<[f64; 3]>,
}

/// The step's increment of every node id as an affine function of its
/// current position: `Δ(x) = value + slope (x − x_current)`.
#[derive(Debug, Clone, Copy)]
pub struct Increment<'a> {
    pub value: &'a [[f64; 3]],
    pub slope: f64,
}

/// Dynamics: the integrator's velocity `v = dv_du · u + offset` per local
/// DOF; the increment is then `Δt v`.
#[derive(Debug, Clone, Copy)]
pub struct Rate<'a> {
    pub dt: f64,
    pub dv_du: f64,
    pub offset: &'a [f64],
    /// Velocity of a rigid master (its prescribed motion per unit time).
    pub master_velocity: [f64; 3],
}

/// One segment's contributions to the node aggregates.
#[derive(Debug, Clone, Copy)]
pub struct SegmentSlip<T> {
    /// `A_s ν_s` (the same for every row).
    pub normal: Vec3<T>,
    /// Per slave row `a`: `Σ_k D_ak Δ¹_k − Σ_l M_al Δ²_l`.
    pub slip: [Vec3<T>; MAX_FACET_NODES],
}

/// Every segment's slip terms (same order as `segments`).
pub fn segment_slips<T: Seed>(
    interface: &Interface,
    segments: &[Segment<T>],
    inc: &Increment,
) -> Vec<SegmentSlip<T>> {
    segments
        .iter()
        .map(|seg| segment_slip(interface, seg, inc))
        .collect()
}

/// One segment's slip terms.
pub fn segment_slip<T: Seed>(
    interface: &Interface,
    seg: &Segment<T>,
    inc: &Increment,
) -> SegmentSlip<T> {
    let (ns, nm) = (interface.slave_type.nodes(), interface.master_type.nodes());
    let s_nodes = &interface.slave_facets[seg.slave as usize][..ns];
    let m_nodes = &interface.master_facets[seg.master as usize][..nm];
    // Σ_k D_ak Δ_k: the increment Δ_k depends on node k's own variables
    // only, as `value + slope (x − x_current)`, so each term is `D_ak`
    // scaled by the value, plus `D_ak slope` on that one derivative (a
    // product in `T` passed over every variable: a sixth of the tangent).
    let mut slip = [autodiff::constant3::<T>([0.0; 3]); MAX_FACET_NODES];
    let sides = [
        (s_nodes, &seg.terms.d, 0, 1.0),
        (m_nodes, &seg.terms.m, super::system::MASTER_OFFSET, -1.0),
    ];
    for (a, s) in slip.iter_mut().enumerate().take(ns) {
        for (nodes, coefficients, offset, sign) in sides {
            for (k, (&node, c)) in nodes.iter().zip(&coefficients[a]).enumerate() {
                if c.is_zero() {
                    // A covered facet's D off its diagonal or first segment.
                    continue;
                }
                let value = inc.value[node as usize];
                for (i, si) in s.iter_mut().enumerate() {
                    si.add_scaled(c, sign * value[i]);
                    si.add_derivative(offset + 3 * k + i, sign * c.re() * inc.slope);
                }
            }
        }
    }
    SegmentSlip {
        normal: autodiff::scale(&seg.terms.normal, seg.terms.area),
        slip,
    }
}

/// What the friction law needs of one node besides its aggregates.
#[derive(Debug, Clone, Copy)]
pub struct Law {
    pub lambda_n: f64,
    pub penalty_n: f64,
    pub area: f64,
    pub lambda_t: [f64; 3],
    pub penalty_t: f64,
    pub mu: f64,
}

/// The return map of a closed node: `(tT, tangential mean slip, sliding)`.
pub fn traction<T: Scalar>(
    gap: T,
    normal_sum: &Vec3<T>,
    slip: &Vec3<T>,
    law: &Law,
) -> (Vec3<T>, Vec3<T>, bool) {
    let pressure = T::from_f64(law.lambda_n) - gap * (law.penalty_n / law.area);
    let n = autodiff::scale(normal_sum, autodiff::norm(normal_sum).recip());
    let tangential = |v: &Vec3<T>| autodiff::sub(v, &autodiff::scale(&n, autodiff::dot(v, &n)));
    let lambda = tangential(&autodiff::constant3(law.lambda_t));
    let mean_slip = autodiff::scale_f64(&tangential(slip), 1.0 / law.area);
    let trial = autodiff::add(&lambda, &autodiff::scale_f64(&mean_slip, law.penalty_t));
    let size = autodiff::norm(&trial);
    let limit = pressure * law.mu;
    if size.re() > limit.re() && size.re() > 0.0 {
        (autodiff::scale(&trial, limit / size), mean_slip, true)
    } else {
        (trial, mean_slip, false)
    }
}

/// The friction outcome of one node.
#[derive(Debug, Clone, Copy, Default, PartialEq)]
pub struct NodeFriction {
    /// Closed: the node carries friction.
    pub active: bool,
    pub sliding: bool,
    /// `tT_j` (residual sense; the traction on the slave is `−tT_j`).
    pub traction: [f64; 3],
    /// Tangential mean slip `P_j ũ_j / A_j` of the step.
    pub slip: [f64; 3],
    /// `∂tT_i/∂(g̃, a, ũ)`.
    pub derivative: [[f64; AGGREGATES]; 3],
}

/// The law at every closed node, from the segments' terms.
pub fn node_frictions<T: Scalar>(
    interface: &Interface,
    nodal: &NodalData,
    friction: &NodalFriction,
    states: &[NodeState],
    segments: &[Segment<T>],
    slips: &[SegmentSlip<T>],
) -> Vec<NodeFriction> {
    let ns = interface.slave_type.nodes();
    let nn = nodal.nodes.len();
    let (mut normal, mut slip) = (vec![[0.0; 3]; nn], vec![[0.0; 3]; nn]);
    for (seg, s) in segments.iter().zip(slips) {
        for (a, &node) in interface.slave_facets[seg.slave as usize][..ns]
            .iter()
            .enumerate()
        {
            if let Some(j) = nodal.slot_of(node) {
                for i in 0..3 {
                    normal[j][i] += s.normal[i].re();
                    slip[j][i] += s.slip[a][i].re();
                }
            }
        }
    }
    (0..nn)
        .map(|j| node_law(nodal, friction, states, j, &normal[j], &slip[j]))
        .collect()
}

/// The law at node `j` (slot) from its aggregates `a_j` (`normal`) and
/// `ũ_j` (`slip`), with their derivatives; an open node carries none.
pub(super) fn node_law(
    nodal: &NodalData,
    friction: &NodalFriction,
    states: &[NodeState],
    j: usize,
    normal: &[f64; 3],
    slip: &[f64; 3],
) -> NodeFriction {
    if !states[j].closed {
        return NodeFriction::default();
    }
    let law = Law {
        lambda_n: nodal.lambda[j],
        penalty_n: nodal.penalty[j],
        area: nodal.area[j],
        lambda_t: friction.lambda[j],
        penalty_t: friction.penalty[j],
        mu: friction.mu,
    };
    let var = |v: f64, i: usize| Dual::<AGGREGATES>::variable(v, i);
    let (t, s, sliding) = traction(
        var(states[j].weighted_gap, 0),
        &[0, 1, 2].map(|i| var(normal[i], 1 + i)),
        &[0, 1, 2].map(|i| var(slip[i], 4 + i)),
        &law,
    );
    NodeFriction {
        active: true,
        sliding,
        traction: autodiff::re3(&t),
        slip: autodiff::re3(&s),
        derivative: t.map(|c| c.eps),
    }
}

/// The tangential force coefficient of slave row `a` on segment node slot
/// `b` (`< 4` slave, else master `b − 4`): `D_ab` or `−M_a(b−4)`.
fn coefficient<T: Scalar>(seg: &Segment<T>, a: usize, b: usize) -> T {
    if b < MAX_FACET_NODES {
        seg.terms.d[a][b]
    } else {
        -seg.terms.m[a][b - MAX_FACET_NODES]
    }
}

/// Adds the tangential residual of the assembled segments.
pub fn residual<T: Scalar>(
    interface: &Interface,
    nodal: &NodalData,
    segments: &[Segment<T>],
    frictions: &[NodeFriction],
    mut emit: impl FnMut(u32, usize, f64),
) {
    for_each_slave_node(interface, nodal, segments, |seg, a, j, ids| {
        let f = &frictions[j];
        if !f.active || f.traction == [0.0; 3] {
            return;
        }
        for (b, &id) in ids.iter().enumerate().filter(|e| *e.1 != u32::MAX) {
            let c = coefficient(seg, a, b).re();
            for (i, t) in f.traction.iter().enumerate() {
                emit(id, i, c * t);
            }
        }
    });
}

/// Adds the exact tangent of the normal and the tangential residual (what
/// a frictional pair assembles). `segments` and `slips` must hold every
/// segment of every node of an assembled facet.
#[allow(clippy::too_many_arguments)]
pub fn tangent(
    interface: &Interface,
    nodal: &NodalData,
    segments: &[Segment<D>],
    slips: &[SegmentSlip<D>],
    states: &[NodeState],
    frictions: &[NodeFriction],
    mut emit: impl FnMut(NodeDof, NodeDof, f64),
) {
    let mut t = FrictionalTangent::new(interface, nodal, states, frictions);
    for (seg, s) in segments.iter().zip(slips) {
        t.add(seg, s, &mut emit);
    }
    t.finish(emit);
}

/// The normal and tangential tangents of a frictional pair, one segment at
/// a time: a segment's own terms are emitted as one block, the per-node
/// outer products once every segment has been added.
pub struct FrictionalTangent<'a> {
    interface: &'a Interface<'a>,
    nodal: &'a NodalData,
    states: &'a [NodeState],
    frictions: &'a [NodeFriction],
    normal: NormalTangent,
    tangential: FrictionTangent,
    local: Block,
}

impl<'a> FrictionalTangent<'a> {
    pub fn new(
        interface: &'a Interface<'a>,
        nodal: &'a NodalData,
        states: &'a [NodeState],
        frictions: &'a [NodeFriction],
    ) -> Self {
        FrictionalTangent {
            interface,
            nodal,
            states,
            frictions,
            normal: NormalTangent::new(nodal),
            tangential: FrictionTangent::new(nodal),
            local: [[0.0; SEGMENT_DOFS]; SEGMENT_DOFS],
        }
    }

    pub fn add(
        &mut self,
        seg: &Segment<D>,
        slip: &SegmentSlip<D>,
        emit: impl FnMut(NodeDof, NodeDof, f64),
    ) {
        let (interface, nodal) = (self.interface, self.nodal);
        let normal = self
            .normal
            .add(interface, nodal, seg, self.states, &mut self.local);
        let tangential =
            self.tangential
                .add(interface, nodal, seg, slip, self.frictions, &mut self.local);
        if normal || tangential {
            let ids = segment_nodes(interface, seg.slave, seg.master);
            emit_local(&ids, &mut self.local, emit);
        }
    }

    pub fn finish(self, emit: impl FnMut(NodeDof, NodeDof, f64)) {
        self.tangential.finish_with(self.normal, self.nodal, emit);
    }
}

/// The tangential tangent, one segment at a time (as the normal one,
/// [`NormalTangent`], whose segment blocks it adds to).
struct FrictionTangent {
    /// Per active node: ∂tT_i/∂x over all its segments, and the assembled
    /// coefficients D_jk / −M_jl by node id.
    grad: Vec<[Vec<(NodeDof, f64)>; 3]>,
    coef: Vec<Vec<(NodeDof, f64)>>,
}

impl FrictionTangent {
    fn new(nodal: &NodalData) -> Self {
        let nn = nodal.nodes.len();
        FrictionTangent {
            grad: vec![Default::default(); nn],
            coef: vec![Vec::new(); nn],
        }
    }

    /// Adds `seg`'s terms: Σ_j tT_j ∂c/∂x into `local` (rows 3 b + i: node
    /// slot b, component i of tT); true if it added any.
    fn add(
        &mut self,
        interface: &Interface,
        nodal: &NodalData,
        seg: &Segment<D>,
        s: &SegmentSlip<D>,
        frictions: &[NodeFriction],
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
            let f = &frictions[j];
            if !f.active {
                continue;
            }
            let aggregates: [&D; AGGREGATES] = [
                &seg.terms.weighted_gap[a],
                &s.normal[0],
                &s.normal[1],
                &s.normal[2],
                &s.slip[a][0],
                &s.slip[a][1],
                &s.slip[a][2],
            ];
            // ∂tT_i = Σ_r (∂tT_i/∂aggregate_r) ∂aggregate_r, over all
            // segment variables at once (the sums in the order they were
            // taken variable by variable).
            let mut dt = [[0.0; SEGMENT_DOFS]; 3];
            for (dti, row) in dt.iter_mut().zip(&f.derivative) {
                for (r, x) in row.iter().zip(&aggregates) {
                    for (d, e) in dti.iter_mut().zip(&x.eps) {
                        *d += r * e;
                    }
                }
            }
            for (v, &id) in ids
                .iter()
                .flat_map(|id| [id; 3])
                .enumerate()
                .filter(|e| *e.1 != u32::MAX)
            {
                for (g, dti) in self.grad[j].iter_mut().zip(&dt) {
                    if dti[v] != 0.0 {
                        g.push(((id, v % 3), dti[v]));
                    }
                }
            }
            if !assembled {
                continue;
            }
            for (b, &id) in ids.iter().enumerate().filter(|e| *e.1 != u32::MAX) {
                let c = coefficient(seg, a, b);
                if c.is_zero() {
                    // A covered facet's zero D (see `NormalTangent::add`).
                    continue;
                }
                self.coef[j].push(((id, 0), c.re));
                for (i, t) in f.traction.iter().enumerate().filter(|e| *e.1 != 0.0) {
                    any = true;
                    for (l, d) in local[3 * b + i].iter_mut().zip(&c.eps) {
                        *l += t * d;
                    }
                }
            }
        }
        any
    }

    /// This tangent's and `normal`'s per-node parts in one pass: row
    /// `(k, i)` of node `j` gets `c^N_{(k,i)} s_j ∂g̃_j + c^T_k ∂tT_{j,i}`
    /// (`s_j = −ε_j/A_j`), one entry per coupling where the two outer
    /// products emitted two (half of a frictional tangent's entries).
    fn finish_with(
        mut self,
        mut normal: NormalTangent,
        nodal: &NodalData,
        mut emit: impl FnMut(NodeDof, NodeDof, f64),
    ) {
        let mut merger = Merger::new();
        let mut columns = Columns::default();
        for j in 0..self.coef.len() {
            if self.coef[j].is_empty() && normal.rows[j].is_empty() {
                continue;
            }
            let scale = -nodal.penalty[j] / nodal.area[j];
            let grad_n = merger.merged(&std::mem::take(&mut normal.grad[j]));
            let grad_t = std::mem::take(&mut self.grad[j]).map(|g| merger.merged(&g));
            columns.gather(&grad_n, &grad_t);
            let rows_n = merger.merged(&std::mem::take(&mut normal.rows[j]));
            let rows_t = merger.merged(&std::mem::take(&mut self.coef[j]));
            for (row, c_n, c_t) in fused_rows(&rows_n, &rows_t) {
                let i = row.1;
                for (u, col) in columns.keys.iter().enumerate() {
                    let v = c_n * scale * columns.normal[u] + c_t * columns.tangential[i][u];
                    if v != 0.0 {
                        emit(row, *col, v);
                    }
                }
            }
        }
    }
}

/// The union of a node's normal and tangential gradient columns, with each
/// gradient's value there (zero where it has none).
#[derive(Default)]
struct Columns {
    keys: Vec<NodeDof>,
    normal: Vec<f64>,
    tangential: [Vec<f64>; 3],
}

impl Columns {
    /// `normal` and `tangential` are merged (sorted, unique keys).
    fn gather(&mut self, normal: &[(NodeDof, f64)], tangential: &[Vec<(NodeDof, f64)>; 3]) {
        // The sorted union, merged list by list (a sort of the four took
        // 1 % of a frictional run).
        self.keys.clear();
        self.keys.extend(normal.iter().map(|e| e.0));
        for t in tangential {
            let mut union = Vec::with_capacity(self.keys.len() + t.len());
            let (mut a, mut b) = (
                self.keys.iter().peekable(),
                t.iter().map(|e| e.0).peekable(),
            );
            loop {
                let next = match (a.peek(), b.peek()) {
                    (None, None) => break,
                    (Some(_), None) => a.next().copied(),
                    (None, Some(_)) => b.next(),
                    (Some(x), Some(y)) if **x < *y => a.next().copied(),
                    (Some(x), Some(y)) if *y < **x => b.next(),
                    _ => {
                        b.next();
                        a.next().copied()
                    }
                };
                union.extend(next);
            }
            self.keys = union;
        }
        let n = self.keys.len();
        let spread = |out: &mut Vec<f64>, from: &[(NodeDof, f64)], keys: &[NodeDof]| {
            out.clear();
            out.resize(n, 0.0);
            let mut u = 0;
            for (k, v) in from {
                while keys[u] != *k {
                    u += 1;
                }
                out[u] = *v;
            }
        };
        spread(&mut self.normal, normal, &self.keys);
        for (out, t) in self.tangential.iter_mut().zip(tangential) {
            spread(out, t, &self.keys);
        }
    }
}

/// The rows of a node's two outer products: the normal coefficients by
/// `(id, i)` and the tangential ones by `(id, 0)` (the same for every
/// component), both merged; `(row, c^N, c^T)` for every `(id, i)` of either.
fn fused_rows(
    normal: &[(NodeDof, f64)],
    tangential: &[(NodeDof, f64)],
) -> Vec<(NodeDof, f64, f64)> {
    let mut out = Vec::with_capacity(normal.len().max(3 * tangential.len()));
    let (mut n, mut t) = (normal.iter().peekable(), tangential.iter().peekable());
    loop {
        let id = match (n.peek(), t.peek()) {
            (None, None) => break,
            (Some(a), None) => a.0 .0,
            (None, Some(b)) => b.0 .0,
            (Some(a), Some(b)) => a.0 .0.min(b.0 .0),
        };
        let c_t = match t.peek() {
            Some(b) if b.0 .0 == id => t.next().map_or(0.0, |b| b.1),
            _ => 0.0,
        };
        let mut c_n = [0.0; 3];
        while let Some(a) = n.peek().filter(|a| a.0 .0 == id) {
            c_n[a.0 .1] = a.1;
            n.next();
        }
        for (i, c) in c_n.iter().enumerate() {
            out.push(((id, i), *c, c_t));
        }
    }
    out
}

/// Emits, per active node j, the outer product of its assembled
/// coefficients (`coef[j]`, by row node) with the gradient of its
/// tangential traction (`grad[j]`, per component): the chain-rule part of
/// the tangential tangent, the same for deformable and rigid masters.
pub(super) fn emit_outer(
    mut coef: Vec<Vec<(NodeDof, f64)>>,
    mut grad: Vec<[Vec<(NodeDof, f64)>; 3]>,
    mut emit: impl FnMut(NodeDof, NodeDof, f64),
) {
    let nn = coef.len();
    let mut merger = Merger::new();
    for j in 0..nn {
        if coef[j].is_empty() {
            continue;
        }
        let rows = merger.merged(&std::mem::take(&mut coef[j]));
        for (i, g) in std::mem::take(&mut grad[j]).iter().enumerate() {
            let g = merger.merged(g);
            for ((id, _), c) in &rows {
                for (col, dt) in &g {
                    let v = c * dt;
                    if v != 0.0 {
                        emit((*id, i), *col, v);
                    }
                }
            }
        }
    }
}
