//! The files a run writes, and the refusal to write any of them over a file
//! the run reads (`-o scene.toml` would replace the scene with HDF5).
use std::path::{Path, PathBuf};

/// A file the run reads, and what it is (for the message).
#[derive(Debug, Clone)]
pub struct Input {
    pub what: &'static str,
    pub path: PathBuf,
}

/// The result file and the sidecars written next to it: the XDMF index and
/// the per-step CSV history.
pub fn written_files(h5: &Path) -> [(&'static str, PathBuf); 3] {
    [
        ("result file", h5.to_path_buf()),
        ("XDMF sidecar", super::xdmf::sidecar_path(h5)),
        ("CSV history", h5.with_extension("csv")),
    ]
}

/// Refuses an output `h5` when it, or a sidecar written next to it, is one
/// of `inputs`, or when two of the written files are one (`-o out.xmf`).
/// Paths are compared canonicalized (symbolic links, `..`, relative paths);
/// a file that does not exist yet is compared through its directory.
pub fn check_not_input(h5: &Path, inputs: &[Input]) -> Result<(), String> {
    let written = written_files(h5);
    for (i, (what, path)) in written.iter().enumerate() {
        let key = canonical(path);
        if let Some(input) = inputs.iter().find(|input| canonical(&input.path) == key) {
            let via = match i {
                0 => String::new(),
                _ => format!(": its {what} {}", path.display()),
            };
            return Err(format!(
                "output {}{via} would overwrite the {} {}, an input of this run; give another output file with -o",
                h5.display(),
                input.what,
                input.path.display()
            ));
        }
        if let Some((other, _)) = written[..i].iter().find(|(_, p)| canonical(p) == key) {
            return Err(format!(
                "output {}: the {other} and its {what} would be the same file; give the result file a name ending in .h5",
                h5.display()
            ));
        }
    }
    Ok(())
}

/// Refuses to write `output` (one file, e.g. a plot) over the `input` it
/// is made from.
pub fn check_not_same(output: &Path, input: &Input) -> Result<(), String> {
    if canonical(output) == canonical(&input.path) {
        return Err(format!(
            "output {} would overwrite the {} {}; give another output file with -o",
            output.display(),
            input.what,
            input.path.display()
        ));
    }
    Ok(())
}

/// `path` made absolute and free of links and `..`: its deepest existing
/// ancestor canonicalized, the rest resolved by name. The rest is created
/// as plain directories before writing (the run creates a missing output
/// directory), so `missing/../scene.toml` is `scene.toml`.
fn canonical(path: &Path) -> PathBuf {
    use std::path::Component;
    let absolute = std::path::absolute(path).unwrap_or_else(|_| path.to_path_buf());
    for base in absolute.ancestors() {
        let Ok(mut out) = base.canonicalize() else {
            continue;
        };
        let rest = absolute.strip_prefix(base).unwrap_or(Path::new(""));
        for c in rest.components() {
            match c {
                Component::ParentDir => {
                    out.pop();
                }
                Component::Normal(name) => out.push(name),
                _ => {}
            }
        }
        return out;
    }
    absolute
}

#[cfg(test)]
mod tests {
    use super::*;

    fn scratch(name: &str) -> PathBuf {
        let dir = std::env::temp_dir().join(format!("contactlink-paths-{name}"));
        let _ = std::fs::remove_dir_all(&dir);
        std::fs::create_dir_all(dir.join("sub")).unwrap();
        dir
    }

    #[test]
    fn outputs_over_inputs_are_refused_through_any_spelling() {
        let dir = scratch("inputs");
        let scene = dir.join("scene.toml");
        let mesh = dir.join("mesh.msh");
        let from = dir.join("first.h5");
        for f in [&scene, &mesh, &from] {
            std::fs::write(f, "x").unwrap();
        }
        let inputs = [
            Input {
                what: "scene file",
                path: scene.clone(),
            },
            Input {
                what: "mesh file",
                path: mesh.clone(),
            },
            Input {
                what: "restart file",
                path: from.clone(),
            },
        ];
        // The same file, spelled through a sub-directory and `..`.
        let e = check_not_input(&dir.join("sub/../scene.toml"), &inputs).unwrap_err();
        assert!(e.contains("would overwrite the scene file"), "{e}");
        // ... and through a directory that does not exist yet (a run
        // creates it before writing).
        let e = check_not_input(&dir.join("new/../mesh.msh"), &inputs).unwrap_err();
        assert!(e.contains("would overwrite the mesh file"), "{e}");
        // A sidecar: out `mesh.h5` writes `mesh.xmf` and `mesh.csv`; a mesh
        // named `mesh.csv` would be overwritten by the history.
        let csv_mesh = [Input {
            what: "mesh file",
            path: dir.join("mesh.csv"),
        }];
        let e = check_not_input(&dir.join("mesh.h5"), &csv_mesh).unwrap_err();
        assert!(e.contains("its CSV history"), "{e}");
        assert!(e.contains("would overwrite the mesh file"), "{e}");
        let e = check_not_input(&dir.join("first.h5"), &inputs).unwrap_err();
        assert!(e.contains("restart file"), "{e}");
        // Its own sidecar.
        let e = check_not_input(&dir.join("out.xmf"), &[]).unwrap_err();
        assert!(e.contains("the result file and its XDMF sidecar"), "{e}");
        let plot = check_not_same(&dir.join("sub/../first.h5"), &inputs[2]).unwrap_err();
        assert!(plot.contains("would overwrite the restart file"), "{plot}");
        assert!(check_not_same(&dir.join("first.png"), &inputs[2]).is_ok());
        // A new file in the same directory is fine.
        assert!(check_not_input(&dir.join("out.h5"), &inputs).is_ok());
        assert!(check_not_input(Path::new("no-such-dir/out.h5"), &inputs).is_ok());
    }
}
