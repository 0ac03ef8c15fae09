//! XDMF 3 sidecar describing a result file to ParaView / VisIt.
//!
//! Shape: one `Domain` holding a `Temporal` collection of `Uniform` grids,
//! one grid per step with `<Time Value=step time>`. Every grid repeats the
//! same Topology (`/mesh/cells`) and Geometry (`/mesh/nodes`) DataItems
//! rather than using XInclude/xpointer references, because plain repeated
//! items are understood by every XDMF reader (and by a plain XML parser in
//! tests) at the cost of a few hundred bytes per step. Attributes per grid:
//! every nodal and cell field of the step, then `partition` and `cell_body`
//! (Scalar, Cell).
//!
//! The writer keeps the sidecar open and, per step, writes the new grid and
//! the fixed closing tail over the old tail in one write ([`Sidecar`]), so
//! the file is a complete document after every step and each step costs the
//! same few kilobytes however many steps came before (rewriting the whole
//! file made the output cost of a run grow with the square of its steps).
//!
//! HDF5 references use the bare file name (`out.h5:/mesh/nodes`), which
//! XDMF readers resolve relative to the `.xmf` file, so the pair can be
//! moved or copied together.

use std::fmt::Write as _;
use std::fs::File;
use std::io;
use std::os::unix::fs::FileExt as _;
use std::path::{Path, PathBuf};

use super::layout;
use crate::fem::CellType;

/// The mesh part of the sidecar: what every grid references.
#[derive(Debug, Clone)]
pub(crate) struct MeshDesc {
    /// File name of the HDF5 file (no directory), as written into DataItems.
    pub h5_name: String,
    pub cell_type: CellType,
    pub n_nodes: usize,
    pub n_cells: usize,
}

/// Where a step field lives: on nodes (N rows) or cells (M rows).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub(crate) enum Center {
    Node,
    Cell,
}

/// One f64 field of a step, stored as `(rows, cols)` at `/steps/<NNNNNN>/<name>`.
#[derive(Debug, Clone)]
pub(crate) struct FieldDesc {
    pub name: String,
    pub cols: usize,
    pub center: Center,
}

/// One step grid.
#[derive(Debug, Clone)]
pub(crate) struct StepDesc {
    pub group: String,
    pub time: f64,
    pub fields: Vec<FieldDesc>,
}

/// `out.h5` -> `out.xmf` in the same directory.
pub fn sidecar_path(h5_path: &Path) -> PathBuf {
    h5_path.with_extension("xmf")
}

/// What follows the last step grid: it closes the collection and the document.
const TAIL: &str = "    </Grid>\n  </Domain>\n</Xdmf>\n";

/// Renders the whole sidecar for `steps` (in the order given).
pub(crate) fn render(mesh: &MeshDesc, steps: &[StepDesc]) -> String {
    let mut s = String::new();
    s.push_str("<?xml version=\"1.0\" encoding=\"utf-8\"?>\n");
    s.push_str("<Xdmf Version=\"3.0\">\n  <Domain>\n");
    s.push_str(
        "    <Grid Name=\"contactlink\" GridType=\"Collection\" CollectionType=\"Temporal\">\n",
    );
    for step in steps {
        render_step(&mut s, mesh, step);
    }
    s.push_str(TAIL);
    s
}

/// The sidecar as its writer keeps it: open, with the offset where the
/// closing tail starts (where the next grid goes).
pub(crate) struct Sidecar {
    file: File,
    tail_at: u64,
}

impl Sidecar {
    /// Writes the document with no steps (through a rename, replacing any
    /// stale sidecar whole) and keeps it open for [`Sidecar::append`].
    pub(crate) fn create(path: &Path, mesh: &MeshDesc) -> io::Result<Sidecar> {
        let text = render(mesh, &[]);
        write_atomic(path, &text)?;
        let file = std::fs::OpenOptions::new().write(true).open(path)?;
        Ok(Sidecar {
            file,
            tail_at: (text.len() - TAIL.len()) as u64,
        })
    }

    /// Adds one step's grid: the grid and the tail are written over the old
    /// tail in a single positioned write (the file only grows, nothing after
    /// the tail is left over). Returns the bytes written, which do not
    /// depend on how many steps the file already lists.
    pub(crate) fn append(&mut self, mesh: &MeshDesc, step: &StepDesc) -> io::Result<usize> {
        let mut s = String::new();
        render_step(&mut s, mesh, step);
        let grid = s.len() as u64;
        s.push_str(TAIL);
        self.file.write_all_at(s.as_bytes(), self.tail_at)?;
        self.tail_at += grid;
        Ok(s.len())
    }
}

/// XDMF's topology name of a cell type. ParaView's XDMF reader maps each to
/// the VTK cell of the same shape and takes the connectivity as it is, so
/// `/mesh/cells` holds VTK's node order.
fn topology(cell: CellType) -> &'static str {
    match cell {
        CellType::Hex8 => "Hexahedron",
        CellType::Tet4 => "Tetrahedron",
        CellType::Tet10 => "Tetrahedron_10",
        CellType::Hex20 => "Hexahedron_20",
        CellType::Hex27 => "Hexahedron_27",
        CellType::Wedge6 => "Wedge",
        CellType::Wedge15 => "Wedge_15",
        CellType::Pyramid5 => "Pyramid",
    }
}

fn render_step(s: &mut String, mesh: &MeshDesc, step: &StepDesc) {
    let h5 = escape(&mesh.h5_name);
    let group = escape(&step.group);
    let (topo, k) = (topology(mesh.cell_type), mesh.cell_type.nodes());
    // `write!` into a String cannot fail; the results are ignored on purpose
    // (`let _`) so that no error path or panic exists here.
    let _ = writeln!(s, "      <Grid Name=\"step_{group}\" GridType=\"Uniform\">");
    let _ = writeln!(s, "        <Time Value=\"{}\"/>", fmt_f64(step.time));
    let _ = writeln!(
        s,
        "        <Topology TopologyType=\"{topo}\" NumberOfElements=\"{}\" NodesPerElement=\"{k}\">",
        mesh.n_cells
    );
    data_item(
        s,
        "Int",
        8,
        &dims(mesh.n_cells, k, false),
        &h5,
        layout::MESH_CELLS,
    );
    s.push_str("        </Topology>\n");
    s.push_str("        <Geometry GeometryType=\"XYZ\">\n");
    data_item(
        s,
        "Float",
        8,
        &dims(mesh.n_nodes, 3, false),
        &h5,
        layout::MESH_NODES,
    );
    s.push_str("        </Geometry>\n");
    for f in &step.fields {
        let (center, rows) = match f.center {
            Center::Node => ("Node", mesh.n_nodes),
            Center::Cell => ("Cell", mesh.n_cells),
        };
        let _ = writeln!(
            s,
            "        <Attribute Name=\"{}\" AttributeType=\"{}\" Center=\"{center}\">",
            escape(&f.name),
            attribute_type(f.cols)
        );
        let h5path = format!("{}/{group}/{}", layout::STEPS, escape(&f.name));
        data_item(s, "Float", 8, &dims(rows, f.cols, false), &h5, &h5path);
        s.push_str("        </Attribute>\n");
    }
    for name in [layout::PARTITION, layout::CELL_BODY] {
        let _ = writeln!(
            s,
            "        <Attribute Name=\"{name}\" AttributeType=\"Scalar\" Center=\"Cell\">"
        );
        let h5path = format!("{}/{name}", layout::MESH);
        data_item(s, "Int", 4, &dims(mesh.n_cells, 1, true), &h5, &h5path);
        s.push_str("        </Attribute>\n");
    }
    s.push_str("      </Grid>\n");
}

fn data_item(
    s: &mut String,
    number_type: &str,
    precision: usize,
    dims: &str,
    h5: &str,
    h5path: &str,
) {
    let _ = writeln!(
        s,
        "          <DataItem Format=\"HDF\" NumberType=\"{number_type}\" Precision=\"{precision}\" \
         Dimensions=\"{dims}\">{h5}:{h5path}</DataItem>"
    );
}

fn dims(rows: usize, cols: usize, one_d: bool) -> String {
    if one_d {
        format!("{rows}")
    } else {
        format!("{rows} {cols}")
    }
}

/// XDMF attribute type by component count; anything without a name of its
/// own is a Matrix (ParaView shows it as a multi-component array).
fn attribute_type(cols: usize) -> &'static str {
    match cols {
        1 => "Scalar",
        3 => "Vector",
        6 => "Tensor6",
        9 => "Tensor",
        _ => "Matrix",
    }
}

/// Shortest text that parses back to the same f64 (Rust's `{:?}` switches to
/// exponent form for very large/small magnitudes, which strtod reads).
fn fmt_f64(v: f64) -> String {
    format!("{v:?}")
}

/// Escapes the five XML special characters (names come from the caller).
fn escape(text: &str) -> String {
    let mut out = String::with_capacity(text.len());
    for c in text.chars() {
        match c {
            '&' => out.push_str("&amp;"),
            '<' => out.push_str("&lt;"),
            '>' => out.push_str("&gt;"),
            '"' => out.push_str("&quot;"),
            '\'' => out.push_str("&apos;"),
            _ => out.push(c),
        }
    }
    out
}

/// Writes `text` to `path` through a temporary file and a rename, so a run
/// killed mid-write leaves the previous complete sidecar, never a torn one.
pub(crate) fn write_atomic(path: &Path, text: &str) -> io::Result<()> {
    let mut tmp = path.as_os_str().to_os_string();
    tmp.push(".tmp");
    let tmp = PathBuf::from(tmp);
    std::fs::write(&tmp, text)?;
    std::fs::rename(&tmp, path)
}

#[cfg(test)]
mod tests {
    use super::*;

    fn mesh() -> MeshDesc {
        MeshDesc {
            h5_name: "out.h5".into(),
            cell_type: CellType::Hex8,
            n_nodes: 12,
            n_cells: 2,
        }
    }

    fn step(i: usize, t: f64) -> StepDesc {
        StepDesc {
            group: super::super::step_group_name(i),
            time: t,
            fields: vec![
                FieldDesc {
                    name: "displacement".into(),
                    cols: 3,
                    center: Center::Node,
                },
                FieldDesc {
                    name: "stress<&>".into(),
                    cols: 6,
                    center: Center::Cell,
                },
            ],
        }
    }

    #[test]
    fn sidecar_name() {
        assert_eq!(
            sidecar_path(Path::new("/a/b/out.h5")),
            Path::new("/a/b/out.xmf")
        );
        assert_eq!(sidecar_path(Path::new("run")), Path::new("run.xmf"));
    }

    #[test]
    fn render_lists_each_step_with_relative_refs() {
        let text = render(&mesh(), &[step(1, 0.5), step(2, 1.0)]);
        assert_eq!(text.matches("GridType=\"Uniform\"").count(), 2);
        assert!(text.contains("<Time Value=\"0.5\"/>"));
        assert!(text.contains("<Time Value=\"1.0\"/>"));
        assert!(text.contains("TopologyType=\"Hexahedron\" NumberOfElements=\"2\""));
        assert!(text.contains("Dimensions=\"12 3\">out.h5:/mesh/nodes<"));
        assert!(text.contains("Dimensions=\"2 8\">out.h5:/mesh/cells<"));
        assert!(text.contains(">out.h5:/steps/000002/displacement<"));
        assert!(
            text.contains("Name=\"stress&lt;&amp;&gt;\" AttributeType=\"Tensor6\" Center=\"Cell\"")
        );
        assert!(text.contains("Precision=\"4\" Dimensions=\"2\">out.h5:/mesh/partition<"));
        // Data references are relative to the sidecar: none starts with `/`.
        assert!(!text.contains(">/") && !text.contains("stress<"));
    }

    #[test]
    fn empty_collection_is_still_a_document() {
        let text = render(&mesh(), &[]);
        assert!(text.starts_with("<?xml"));
        assert!(text.trim_end().ends_with("</Xdmf>"));
        assert!(!text.contains("Uniform"));
    }

    #[test]
    fn float_text_round_trips() {
        for v in [0.0, 0.1, 1.0, 1e-7, 2.5e300, -3.25] {
            let back: f64 = fmt_f64(v).parse().unwrap_or(f64::NAN);
            assert_eq!(back, v);
        }
    }

    /// Whether `text` is one well-formed element tree (tags balanced and
    /// properly nested, nothing but whitespace after the root).
    fn well_formed(text: &str) -> bool {
        let body = match text.strip_prefix("<?xml") {
            Some(rest) => match rest.find("?>") {
                Some(i) => &rest[i + 2..],
                None => return false,
            },
            None => text,
        };
        let mut open: Vec<&str> = Vec::new();
        let mut rest = body;
        let mut roots = 0;
        while let Some(start) = rest.find('<') {
            let Some(len) = rest[start..].find('>') else {
                return false;
            };
            let tag = &rest[start + 1..start + len];
            rest = &rest[start + len + 1..];
            if let Some(name) = tag.strip_prefix('/') {
                if open.pop() != Some(name.trim()) {
                    return false;
                }
            } else {
                if open.is_empty() {
                    roots += 1;
                }
                if !tag.ends_with('/') {
                    open.push(tag.split_whitespace().next().unwrap_or(""));
                }
            }
        }
        open.is_empty() && roots == 1 && rest.trim().is_empty()
    }

    #[test]
    fn appended_sidecar_is_the_full_document_after_every_step() {
        let dir = std::env::temp_dir().join(format!("xdmf_append_{}", std::process::id()));
        let _ = std::fs::create_dir_all(&dir);
        let p = dir.join("out.xmf");
        // A stale, longer sidecar is replaced, not partly overwritten.
        let stale = render(&mesh(), &(1..=20).map(|i| step(i, 0.1)).collect::<Vec<_>>());
        std::fs::write(&p, stale).unwrap();
        let mut sidecar = Sidecar::create(&p, &mesh()).unwrap();
        let read = || std::fs::read_to_string(&p).unwrap();
        assert_eq!(read(), render(&mesh(), &[]));
        assert!(well_formed(&read()));
        let mut steps = Vec::new();
        for i in 1..=12 {
            steps.push(step(i, 0.25 * i as f64));
            sidecar.append(&mesh(), &steps[i - 1]).unwrap();
            let text = read();
            assert_eq!(text, render(&mesh(), &steps), "after step {i}");
            assert!(well_formed(&text), "after step {i}");
            assert_eq!(text.matches("GridType=\"Uniform\"").count(), i);
        }
        assert!(!well_formed("<a><b></a></b>") && !well_formed("<a></a><a/>"));
        let _ = std::fs::remove_dir_all(&dir);
    }

    #[test]
    fn bytes_written_per_step_do_not_grow_with_the_step_index() {
        let dir = std::env::temp_dir().join(format!("xdmf_cost_{}", std::process::id()));
        let _ = std::fs::create_dir_all(&dir);
        let p = dir.join("out.xmf");
        let mut sidecar = Sidecar::create(&p, &mesh()).unwrap();
        // Same time text for every step, so only the index could matter.
        let written: Vec<usize> = (1..=3000)
            .map(|i| sidecar.append(&mesh(), &step(i, 1.0)).unwrap())
            .collect();
        assert!(
            written.iter().all(|&n| n == written[0]),
            "{:?}",
            &written[..3]
        );
        let total = std::fs::metadata(&p).unwrap().len() as usize;
        let grid = written[0] - TAIL.len();
        assert_eq!(total, render(&mesh(), &[]).len() + 3000 * grid);
        let _ = std::fs::remove_dir_all(&dir);
    }

    #[test]
    fn atomic_write_replaces() {
        let dir = std::env::temp_dir().join(format!("xdmf_atomic_{}", std::process::id()));
        let _ = std::fs::create_dir_all(&dir);
        let p = dir.join("a.xmf");
        assert!(write_atomic(&p, "one").is_ok());
        assert!(write_atomic(&p, "two").is_ok());
        assert_eq!(std::fs::read_to_string(&p).ok().as_deref(), Some("two"));
        assert!(!dir.join("a.xmf.tmp").exists());
        let _ = std::fs::remove_dir_all(&dir);
    }
}
