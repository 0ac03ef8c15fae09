//! Where a scene key was written, for error messages.
//!
//! The serde structs of `sections.rs` keep no spans, and wrapping every field in
//! `toml::Spanned` would change every struct and every use. Errors are rare,
//! so instead the scene text is parsed a second time, with `toml_edit`'s
//! span-keeping `ImDocument`, only when an error needs its line.
use toml_edit::{ImDocument, Item};

/// One step of a key path: a table key, or an entry of an array of tables
/// (`[[body]]` number N, from 0).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Seg {
    Key(&'static str),
    Index(usize),
}

/// Where a key's value came from.
#[derive(Debug, Clone, PartialEq, Eq)]
pub enum Origin {
    /// Line (from 1) in the scene text of the key, or of the nearest enclosing
    /// table when the key itself is absent (a missing key, a default).
    Line(usize),
    /// A `--set` override (as given) supplied the value.
    Override(String),
    /// Not found (a built-up value, or a scene without that section).
    Unknown,
}

/// The scene text and its `--set` overrides, kept to locate keys later.
#[derive(Debug, Clone, Default)]
pub struct KeyLines {
    text: String,
    overrides: Vec<String>,
}

impl KeyLines {
    pub fn new(text: &str, overrides: &[String]) -> Self {
        KeyLines {
            text: text.to_owned(),
            overrides: overrides.to_vec(),
        }
    }

    /// Where the key at `path` was set: an override naming it wins (it
    /// replaced whatever the file said), else its line in the file.
    pub fn locate(&self, path: &[Seg]) -> Origin {
        if let Some(o) = self
            .overrides
            .iter()
            .rev()
            .find(|o| override_matches(o, path))
        {
            return Origin::Override(o.clone());
        }
        match self.span_start(path) {
            Some(offset) => Origin::Line(line_of(&self.text, offset)),
            None => Origin::Unknown,
        }
    }

    /// Byte offset of the deepest item along `path` that has a span.
    fn span_start(&self, path: &[Seg]) -> Option<usize> {
        let doc = ImDocument::parse(self.text.as_str()).ok()?;
        let mut item: &Item = doc.as_item();
        let mut found = None;
        for seg in path {
            let next = match seg {
                Seg::Key(k) => item.get(*k),
                Seg::Index(i) => item.get(*i),
            };
            match next {
                Some(n) => {
                    item = n;
                    found = n.span().map(|s| s.start).or(found);
                }
                None => break,
            }
        }
        found
    }
}

/// The `[mesh]` keys a generator's spec fields are read from (the same
/// names, without an index such as `divisions[2]`).
const MESH_KEYS: &[&str] = &[
    "body",
    "origin",
    "size",
    "divisions",
    "grading",
    "cell_type",
    "radius",
    "block_width",
    "block_height",
    "thickness",
    "gap",
    "fine_size",
    "fine_half_width",
    "growth",
    "level",
    "length",
    "height",
    "lower_divisions",
    "upper_divisions",
];

/// The `[mesh]` key a generator error is about, if it names one.
pub fn mesh_key(e: &crate::mesh::MeshError) -> Option<&'static str> {
    let crate::mesh::MeshError::InvalidSpec { field, .. } = e else {
        return None;
    };
    let name = field.split('[').next().unwrap_or(field);
    MESH_KEYS.iter().copied().find(|k| *k == name)
}

/// Line number (from 1) of a byte offset.
pub fn line_of(text: &str, offset: usize) -> usize {
    text.as_bytes()[..offset.min(text.len())]
        .iter()
        .filter(|&&b| b == b'\n')
        .count()
        + 1
}

/// Whether `--set a.b.c=v` assigned the key at `path`. An index may be left
/// out of an override when the array has a single entry (`body.poisson`
/// sets `body.0.poisson`), as `apply_override` allows.
fn override_matches(assignment: &str, path: &[Seg]) -> bool {
    let Some((keys, _)) = assignment.split_once('=') else {
        return false;
    };
    let mut keys = keys.trim().split('.').peekable();
    for seg in path {
        match seg {
            Seg::Key(k) => {
                if keys.next() != Some(*k) {
                    return false;
                }
            }
            Seg::Index(i) => match keys.peek().and_then(|k| k.parse::<usize>().ok()) {
                Some(n) => {
                    keys.next();
                    if n != *i {
                        return false;
                    }
                }
                None if *i == 0 => {}
                None => return false,
            },
        }
    }
    keys.next().is_none()
}

#[cfg(test)]
mod tests {
    use super::*;

    const TEXT: &str = "title = \"t\"\n\n[mesh]\ngenerator = \"box\"\n\n[[body]]\nname = \"a\"\npoisson = 0.3\n\n[[body]]\nname = \"b\"\npoisson = 0.5\n";

    #[test]
    fn keys_and_array_entries_have_lines() {
        let l = KeyLines::new(TEXT, &[]);
        use Seg::*;
        assert_eq!(l.locate(&[Key("mesh"), Key("generator")]), Origin::Line(4));
        assert_eq!(
            l.locate(&[Key("body"), Index(1), Key("poisson")]),
            Origin::Line(12)
        );
        // An absent key falls back to its table's header line.
        assert_eq!(
            l.locate(&[Key("body"), Index(1), Key("youngs")]),
            Origin::Line(10)
        );
        assert_eq!(l.locate(&[Key("steps")]), Origin::Unknown);
    }

    #[test]
    fn overrides_win() {
        let o = vec!["body.1.poisson=0.6".to_string()];
        let l = KeyLines::new(TEXT, &o);
        use Seg::*;
        assert_eq!(
            l.locate(&[Key("body"), Index(1), Key("poisson")]),
            Origin::Override(o[0].clone())
        );
        assert_eq!(
            l.locate(&[Key("body"), Index(0), Key("poisson")]),
            Origin::Line(8)
        );
        assert!(override_matches(
            "mesh.poisson=1",
            &[Key("mesh"), Key("poisson")]
        ));
        assert!(override_matches(
            "body.poisson=1",
            &[Key("body"), Index(0), Key("poisson")]
        ));
    }
}
