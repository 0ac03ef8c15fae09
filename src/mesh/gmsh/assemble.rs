//! Assembly of what was read into a validated [`Mesh`]: bodies, node
//! renumbering, cell orientation, facet and node sets.

use std::collections::BTreeMap;

use super::kind::Kind;
use super::sections::{ElementList, Raw};
use super::{GmshError, GmshErrorKind, GmshReport, Location};
use crate::mesh::topology::face_key;
use crate::mesh::{FacetRef, FacetType, Mesh};

/// File name for errors found after parsing.
pub(super) struct Ctx<'a> {
    pub(super) path: &'a str,
}

impl Ctx<'_> {
    fn error(&self, location: Location, kind: GmshErrorKind) -> GmshError {
        GmshError {
            path: self.path.to_string(),
            location,
            kind,
        }
    }

    fn whole_file(&self, kind: GmshErrorKind) -> GmshError {
        self.error(Location::File, kind)
    }
}

pub(super) fn assemble(raw: Raw, ctx: &Ctx) -> Result<(Mesh, GmshReport), GmshError> {
    let kind = raw
        .volume_kind
        .ok_or_else(|| ctx.whole_file(GmshErrorKind::NoVolumeCells))?;
    let cell_type = match kind {
        Kind::Cell(c) => c,
        _ => return Err(ctx.whole_file(GmshErrorKind::NoVolumeCells)),
    };
    let volumes = raw.list(kind);
    let (bodies, cell_body) = assign_bodies(&raw, volumes, ctx)?;
    let new_id = compact_nodes(raw.coords.len(), &volumes.nodes);
    let mut mesh = Mesh::empty(cell_type);
    mesh.nodes = raw
        .coords
        .iter()
        .zip(&new_id)
        .filter(|(_, id)| id.is_some())
        .map(|(x, _)| *x)
        .collect();
    // Every volume node is used, so the lookups all succeed; Gmsh's node
    // order becomes ours.
    let per = cell_type.nodes();
    mesh.cells = match kind.to_ours() {
        None => volumes.nodes.iter().filter_map(|&n| new_id[n]).collect(),
        Some(order) => volumes
            .nodes
            .chunks_exact(per)
            .flat_map(|e| order.iter().filter_map(|&k| new_id[e[k]]))
            .collect(),
    };
    mesh.cell_body = cell_body;
    mesh.bodies = bodies;
    let reoriented = orient_cells(&mut mesh, volumes, ctx)?;
    let sets = SetBuilder {
        raw: &raw,
        new_id: &new_id,
        ctx,
    };
    sets.facet_sets(&mut mesh)?;
    sets.node_sets(&mut mesh)?;
    mesh.validate()
        .map_err(|e| ctx.whole_file(GmshErrorKind::Invalid(e)))?;
    let report = GmshReport {
        reoriented,
        skipped_sections: raw.skipped.clone(),
        unused_nodes: raw.coords.len() - mesh.nodes.len(),
    };
    Ok((mesh, report))
}

/// Body names and each cell's body: 3D physical groups in tag order, or one
/// body per volume entity when the file has no 3D physical group.
fn assign_bodies(
    raw: &Raw,
    volumes: &ElementList,
    ctx: &Ctx,
) -> Result<(Vec<String>, Vec<u32>), GmshError> {
    let has_groups = raw.entity_groups[3].values().any(|g| !g.is_empty())
        || raw.physical_names.keys().any(|&(d, _)| d == 3);
    // (sort key, name) per cell, then bodies numbered in key order.
    let mut keys = Vec::with_capacity(volumes.len());
    for (i, &entity) in volumes.entities.iter().enumerate() {
        if !has_groups {
            keys.push((entity, format!("volume{entity}")));
            continue;
        }
        let at = volumes.locations[i];
        match raw.groups(3, entity) {
            [] => return Err(ctx.error(at, GmshErrorKind::VolumeWithoutPhysical { entity })),
            [g] => keys.push((*g, raw.group_name(3, *g))),
            [a, b, ..] => {
                let kind = GmshErrorKind::VolumeInTwoBodies {
                    entity,
                    first: raw.group_name(3, *a),
                    second: raw.group_name(3, *b),
                };
                return Err(ctx.error(at, kind));
            }
        }
    }
    let mut distinct: Vec<(i32, String)> = keys.clone();
    distinct.sort();
    distinct.dedup();
    let bodies: Vec<String> = distinct.iter().map(|(_, n)| n.clone()).collect();
    let cell_body = keys
        .iter()
        .map(|k| distinct.binary_search(k).unwrap_or(0) as u32)
        .collect();
    Ok((bodies, cell_body))
}

/// New node ids: nodes used by cells, numbered in file order.
fn compact_nodes(num_nodes: usize, cell_nodes: &[usize]) -> Vec<Option<usize>> {
    let mut used = vec![false; num_nodes];
    for &n in cell_nodes {
        used[n] = true;
    }
    let mut next = 0;
    used.iter()
        .map(|&u| {
            u.then(|| {
                next += 1;
                next - 1
            })
        })
        .collect()
}

/// Reverses fully inverted cells (some generators emit them), rejects
/// tangled ones naming the Gmsh element; returns how many were reversed.
pub(super) fn orient_cells(
    mesh: &mut Mesh,
    volumes: &ElementList,
    ctx: &Ctx,
) -> Result<usize, GmshError> {
    crate::mesh::orient::orient_cells(mesh).map_err(|t| {
        let kind = GmshErrorKind::TangledCell {
            element: volumes.tags[t.cell],
            min: t.min,
            max: t.max,
        };
        ctx.error(volumes.locations[t.cell], kind)
    })
}

/// Builds the facet and node sets of the physical groups below dimension 3.
struct SetBuilder<'a> {
    raw: &'a Raw,
    new_id: &'a [Option<usize>],
    ctx: &'a Ctx<'a>,
}

impl SetBuilder<'_> {
    /// Mesh ids of element `i` of `list`, or an error naming the first node
    /// that no cell uses.
    fn element_nodes(
        &self,
        list: &ElementList,
        i: usize,
        per: usize,
        group: &str,
    ) -> Result<Vec<usize>, GmshError> {
        let old = list.nodes.get(i * per..(i + 1) * per).unwrap_or_default();
        old.iter()
            .map(|&n| {
                self.new_id[n].ok_or_else(|| {
                    let kind = GmshErrorKind::NodeNotInCells {
                        element: list.tags[i],
                        group: group.to_string(),
                        node: self.raw.node_tags[n],
                    };
                    self.ctx.error(list.locations[i], kind)
                })
            })
            .collect()
    }

    /// Each element of `kind` in a physical group, with the group's name.
    fn grouped(&self, kind: Kind) -> impl Iterator<Item = (usize, String)> + '_ {
        let list = self.raw.list(kind);
        let dim = kind.dim();
        (0..list.len()).flat_map(move |i| {
            self.raw
                .groups(dim, list.entities[i])
                .iter()
                .map(move |&g| (i, self.raw.group_name(dim, g)))
        })
    }

    fn facet_sets(&self, mesh: &mut Mesh) -> Result<(), GmshError> {
        let boundary = mesh.boundary_faces_by_key();
        let mut facet_sets: BTreeMap<String, Vec<FacetRef>> = BTreeMap::new();
        for facet_type in FacetType::ALL {
            let kind = Kind::Facet(facet_type);
            let list = self.raw.list(kind);
            for (i, group) in self.grouped(kind) {
                let element = list.tags[i];
                let at = list.locations[i];
                let nodes = self.element_nodes(list, i, kind.nodes(), &group)?;
                let corners = &nodes[..facet_type.corners()];
                let facet = boundary.get(&face_key(corners.iter().copied()));
                let Some(&facet) = facet else {
                    let kind = GmshErrorKind::FacetNotOnCell { element, group };
                    return Err(self.ctx.error(at, kind));
                };
                let expected = mesh.facet_type(&facet);
                if expected != facet_type {
                    let kind = GmshErrorKind::FacetTypeMismatch {
                        element,
                        group,
                        found: facet_type.name(),
                        cells: mesh.cell_type.name(),
                        expected: expected.name(),
                    };
                    return Err(self.ctx.error(at, kind));
                }
                insert_nodes(&mut mesh.node_sets, &group, &nodes);
                facet_sets.entry(group).or_default().push(facet);
            }
        }
        for facets in facet_sets.values_mut() {
            facets.sort_unstable();
            facets.dedup();
        }
        mesh.facet_sets = facet_sets;
        finish_node_sets(&mut mesh.node_sets);
        Ok(())
    }

    fn node_sets(&self, mesh: &mut Mesh) -> Result<(), GmshError> {
        for kind in [Kind::Point, Kind::Line, Kind::Line3] {
            let list = self.raw.list(kind);
            for (i, group) in self.grouped(kind) {
                let nodes = self.element_nodes(list, i, kind.nodes(), &group)?;
                insert_nodes(&mut mesh.node_sets, &group, &nodes);
            }
        }
        finish_node_sets(&mut mesh.node_sets);
        Ok(())
    }
}

fn insert_nodes(sets: &mut BTreeMap<String, Vec<usize>>, name: &str, nodes: &[usize]) {
    sets.entry(name.to_string())
        .or_default()
        .extend_from_slice(nodes);
}

fn finish_node_sets(sets: &mut BTreeMap<String, Vec<usize>>) {
    for nodes in sets.values_mut() {
        nodes.sort_unstable();
        nodes.dedup();
    }
}
