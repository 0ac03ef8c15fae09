//! The run's result file: created with the mesh and run metadata before the
//! first step, then written by [`Hdf5Sink`] after every converged step.

use std::collections::BTreeMap;
use std::path::Path;

use super::{layout, BlockRows, FacetSetOut, MeshHeader, ResultFile, StepInfo, MIXED_FACETS};
use crate::distribution::LocalMesh;
use crate::dofs::even_block;
use crate::error::Result;
use crate::fem::FacetType;
use crate::hertz::{HertzCheck, HertzKind};
use crate::petsc::Vector;
use crate::runtime::Runtime;
use crate::solve::{NaturalOrder, PairFields, Simulation, StepReport, StepSink};

/// Where a run came from, stored in the result file (`/scene`,
/// `/scene_overrides`) so a result can be traced to its input.
#[derive(Debug, Clone, Default)]
pub struct Provenance {
    /// The scene's TOML text as loaded (before overrides).
    pub scene: String,
    /// The `--set key=value` overrides, in order.
    pub overrides: Vec<String>,
}

/// Scatters of one contact pair's point arrays into output order.
struct PairOrder {
    scalar: NaturalOrder,
    vector: NaturalOrder,
    rows: usize,
}

/// Writes every converged step to the HDF5 file, in natural (input) order.
pub struct Hdf5Sink {
    file: ResultFile,
    natural: NaturalOrder,
    natural_scalar: NaturalOrder,
    pairs: Vec<PairOrder>,
    nodes: usize,
}

impl Hdf5Sink {
    pub fn new(file: ResultFile, sim: &Simulation) -> Result<Self> {
        let dofs = sim.dofs();
        let mut pairs = Vec::new();
        for p in sim.contact() {
            let slave = p.slave();
            let nqp = slave.nqp;
            let rows = slave.global_facets * nqp;
            let petsc_row = |nat: usize| slave.global_point(nat / nqp, nat % nqp);
            let owned = slave.num_qps();
            pairs.push(PairOrder {
                scalar: NaturalOrder::new(rows, 1, owned, petsc_row, dofs.rank, dofs.nranks)?,
                vector: NaturalOrder::new(rows, 3, owned, petsc_row, dofs.rank, dofs.nranks)?,
                rows,
            });
        }
        Ok(Hdf5Sink {
            file,
            natural: NaturalOrder::nodal(dofs)?,
            natural_scalar: NaturalOrder::nodal_scalar(dofs)?,
            pairs,
            nodes: dofs.num_global_nodes(),
        })
    }

    /// A pair's fields of one step: its point fields (rows: the pair's
    /// slave points in input order) and nodal fields (rows: mesh nodes in
    /// input order), whichever its formulation writes, then its force and
    /// penalty (raised when Uzawa was slow, for a restart).
    fn write_pair(
        &mut self,
        step: usize,
        i: usize,
        fields: &PairFields,
        report: &StepReport,
    ) -> Result<()> {
        let name = fields.pair.name();
        let output = &fields.output;
        let order = &mut self.pairs[i];
        for f in &output.point_fields {
            let scatter = if f.cols == 3 {
                &mut order.vector
            } else {
                &mut order.scalar
            };
            let (start, data) = scatter.block_of_owned(&f.values)?;
            self.file.write_step_block(
                step,
                &layout::pair_dataset(name, f.name),
                BlockRows {
                    global_rows: order.rows,
                    start,
                    cols: f.cols,
                    data: &data,
                },
            )?;
        }
        for f in &output.node_fields {
            let scatter = if f.cols == 3 {
                &mut self.natural
            } else {
                &mut self.natural_scalar
            };
            let (start, data) = scatter.block_of_owned(&f.values)?;
            self.file.write_step_block(
                step,
                &layout::pair_dataset(name, f.name),
                BlockRows {
                    global_rows: self.nodes,
                    start,
                    cols: f.cols,
                    data: &data,
                },
            )?;
        }
        let force = report.contact.get(i).map_or([0.0; 3], |c| c.force);
        self.file.write_step_small(
            step,
            &layout::pair_dataset(name, layout::PAIR_FORCE),
            &force,
        )?;
        self.file.write_step_small(
            step,
            &layout::pair_dataset(name, layout::PAIR_PENALTY),
            &[fields.pair.penalty()],
        )?;
        Ok(())
    }
}

impl StepSink for Hdf5Sink {
    fn step(
        &mut self,
        report: &StepReport,
        displacement: &Vector,
        reaction: &Vector,
        contact: &[PairFields],
        nodal_pressure: &[f64],
        velocity: Option<&Vector>,
    ) -> Result<()> {
        let (start, u) = self.natural.block_of(displacement)?;
        let (_, r) = self.natural.block_of(reaction)?;
        let v = velocity.map(|v| self.natural.block_of(v)).transpose()?;
        let info = StepInfo {
            index: report.index,
            time: report.dynamics.map_or(report.load_factor, |d| d.time),
            load_factor: report.load_factor,
            newton_iterations: report.newton_iterations,
            uzawa_iterations: report.uzawa_iterations,
            converged: true,
            wall_seconds: report.wall_seconds,
        };
        let nodal = |data| BlockRows {
            global_rows: self.nodes,
            start,
            cols: 3,
            data,
        };
        let mut fields = vec![
            (layout::DISPLACEMENT, nodal(&u)),
            (layout::REACTION, nodal(&r)),
        ];
        if let Some((_, v)) = &v {
            fields.push((layout::VELOCITY, nodal(v)));
        }
        let p = if contact.is_empty() {
            None
        } else {
            Some(self.natural_scalar.block_of_owned(nodal_pressure)?)
        };
        if let Some((pstart, p)) = &p {
            fields.push((
                layout::CONTACT_PRESSURE,
                BlockRows {
                    global_rows: self.nodes,
                    start: *pstart,
                    cols: 1,
                    data: p,
                },
            ));
        }
        self.file.write_step(&info, &fields, &[])?;
        if let Some(d) = &report.dynamics {
            self.file
                .write_step_small(report.index, layout::ENERGY, &[d.kinetic, d.strain])?;
            self.file
                .write_step_small(report.index, layout::MOMENTUM, &d.momentum)?;
        }
        for (i, fields) in contact.iter().enumerate() {
            self.write_pair(report.index, i, fields, report)?;
        }
        self.file.flush()?;
        Ok(())
    }
}

pub fn create_result_file(
    rt: &Runtime,
    sim: &Simulation,
    path: &Path,
    provenance: Option<&Provenance>,
) -> Result<ResultFile> {
    let model = sim.model();
    let local = sim.local_mesh();
    let (rank, size) = (rt.rank(), rt.size());
    let node_block = even_block(local.global_nodes, rank, size);
    let cell_block = even_block(local.global_cells, rank, size);
    let nodes: Vec<f64> = local.block.nodes.iter().flatten().copied().collect();
    let npc = local.cell_type.nodes();
    // VTK's node order, which XDMF readers take as it is.
    let order = local.cell_type.vtk_order();
    let cells: Vec<i64> = local
        .block
        .cells
        .chunks_exact(npc)
        .flat_map(|c| order.iter().map(move |&k| c[k] as i64))
        .collect();
    let partition: Vec<i32> = sim.partition_block().to_vec();
    let cell_body: Vec<i32> = local.block.cell_body.iter().map(|&b| b as i32).collect();
    let facet_sets = facet_sets_out(local);
    let header = MeshHeader {
        cell_type: local.cell_type.name(),
        nodes: BlockRows {
            global_rows: local.global_nodes,
            start: node_block.start,
            cols: 3,
            data: &nodes,
        },
        cells: BlockRows {
            global_rows: local.global_cells,
            start: cell_block.start,
            cols: npc,
            data: &cells,
        },
        partition: BlockRows {
            global_rows: local.global_cells,
            start: cell_block.start,
            cols: 1,
            data: &partition,
        },
        cell_body: BlockRows {
            global_rows: local.global_cells,
            start: cell_block.start,
            cols: 1,
            data: &cell_body,
        },
        bodies: &local.bodies,
        node_sets: &local.node_sets,
        facet_sets: &facet_sets,
    };
    let mut file = ResultFile::create(&rt.world(), path, &header)?;
    if let Some(p) = provenance {
        let overrides = p.overrides.join("\n");
        file.write_attributes(
            "/",
            &[
                (layout::SCENE_ATTR, &p.scene),
                (layout::SCENE_OVERRIDES_ATTR, &overrides),
            ],
            &[],
        )?;
    }
    if !model.contact.is_empty() {
        // Pair name → slave facet set: lets a reader pick a pair's nodes out
        // of the nodal contact_pressure field (`contactlink summary`).
        let slaves: Vec<(&str, &str)> = model
            .contact
            .iter()
            .map(|p| (p.name.as_str(), p.slave.as_str()))
            .collect();
        file.write_attributes(layout::CONTACT_PAIRS, &slaves, &[])?;
    }
    if let Some(h) = &model.hertz {
        write_hertz_setup(&mut file, h)?;
    }
    Ok(file)
}

/// `/hertz`: what `contactlink plot` needs to draw the closed-form profile
/// (the load comes from each step's contact force).
fn write_hertz_setup(file: &mut ResultFile, h: &HertzCheck) -> Result<()> {
    let (kind, thickness) = match h.kind {
        HertzKind::Line { thickness } => (layout::HERTZ_KIND_LINE, Some(thickness)),
        HertzKind::Point => (layout::HERTZ_KIND_POINT, None),
    };
    let mut numbers = vec![
        (layout::HERTZ_RADIUS_ATTR, h.radius),
        (layout::HERTZ_EFFECTIVE_MODULUS_ATTR, h.effective_modulus),
    ];
    numbers.extend(thickness.map(|t| (layout::HERTZ_THICKNESS_ATTR, t)));
    file.write_attributes(
        layout::HERTZ,
        &[
            (layout::HERTZ_KIND_ATTR, kind),
            (layout::HERTZ_PAIR_ATTR, &h.pair),
        ],
        &numbers,
    )?;
    Ok(())
}

/// Every facet set whole, as every rank received it with its piece. A set
/// of one facet type is written as it is; a set of a wedge's or pyramid's
/// triangles and quadrilaterals as [`MIXED_FACETS`], its rows padded.
fn facet_sets_out(mesh: &LocalMesh) -> BTreeMap<String, FacetSetOut> {
    mesh.shared
        .iter()
        .map(|(name, set)| {
            let types: Vec<FacetType> = set.facet_types(mesh.cell_type).collect();
            let k = types
                .iter()
                .map(|t| t.nodes())
                .max()
                .unwrap_or_else(|| mesh.cell_type.face_type(0).nodes());
            let first = types
                .first()
                .copied()
                .unwrap_or(mesh.cell_type.face_type(0));
            let facet_type = if types.iter().all(|&t| t == first) {
                first.name().to_string()
            } else {
                MIXED_FACETS.to_string()
            };
            let mut nodes = Vec::with_capacity(k * types.len());
            let mut rest = set.nodes.iter();
            for t in &types {
                nodes.extend(rest.by_ref().take(t.nodes()).map(|&v| v as i64));
                nodes.extend(std::iter::repeat_n(-1, k - t.nodes()));
            }
            let out = FacetSetOut {
                facet_type,
                nodes,
                k,
                cell: set.cells.iter().map(|&c| c as i64).collect(),
                face: set.faces.iter().map(|&f| f as i8).collect(),
            };
            (name.clone(), out)
        })
        .collect()
}
