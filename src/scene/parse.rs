//! Scene text → [`Scene`]: `--set` overrides, TOML syntax and schema
//! errors as one line each, and [`Bad`], a semantic error at a key, turned
//! into an error naming that key's line.
use super::lines::{self, KeyLines, Origin, Seg};
use super::{Scene, SceneSource};
use crate::error::{Error, Result};
use serde::Deserialize;

/// Parses a scene, applying `overrides` ("a.b=value", TOML values) first.
pub fn parse(src: &SceneSource, overrides: &[String]) -> Result<Scene> {
    let mut scene = parse_values(src, overrides)?;
    scene.lines = KeyLines::new(&src.text, overrides);
    Ok(scene)
}

pub(super) fn parse_values(src: &SceneSource, overrides: &[String]) -> Result<Scene> {
    if overrides.is_empty() {
        // Straight from the text, so errors carry the line and column.
        return toml::from_str(&src.text).map_err(|e| toml_error(src, &e));
    }
    let mut doc: toml::Table = toml::from_str(&src.text).map_err(|e| toml_error(src, &e))?;
    for o in overrides {
        apply_override(&mut doc, o)
            .map_err(|m| Error::scene(&src.origin, format!("--set {o}: {m}")))?;
    }
    Scene::deserialize(toml::Value::Table(doc)).map_err(|e| {
        // Overridden values carry no spans. An error the file has on its own
        // is located in the file; any other came with the overrides.
        match toml::from_str::<Scene>(&src.text) {
            Err(own) if own.message() == e.message() => toml_error(src, &own),
            _ => {
                let given: Vec<String> = overrides.iter().map(|o| format!("--set {o}")).collect();
                let mut err = toml_error(src, &e);
                if let Error::Scene { message, .. } = &mut err {
                    *message = format!("{}: {message}", given.join(" "));
                }
                err
            }
        }
    })
}

/// A syntax or schema error from toml/serde as one line, `origin:LINE:
/// message` (toml's own rendering spans several lines with a code excerpt).
pub(super) fn toml_error(src: &SceneSource, e: &toml::de::Error) -> Error {
    let message = match e.message().trim() {
        "missing field `mesh`" => {
            "no [mesh] section (the mesh generator and its parameters)".to_owned()
        }
        "missing field `body`" => {
            "no [[body]] section (one per mesh body, with its material)".to_owned()
        }
        m => m.lines().map(str::trim).collect::<Vec<_>>().join("; "),
    };
    match e.span() {
        Some(span) => Error::scene(
            with_line(&src.origin, lines::line_of(&src.text, span.start)),
            message,
        ),
        None => Error::scene(&src.origin, message),
    }
}

pub(super) fn apply_override(
    doc: &mut toml::Table,
    assignment: &str,
) -> std::result::Result<(), String> {
    let (path, value) = assignment
        .split_once('=')
        .ok_or("expected key.path=value")?;
    let parsed: toml::Value = toml::from_str::<toml::Table>(&format!("v = {value}"))
        .ok()
        .and_then(|mut t| t.remove("v"))
        .unwrap_or_else(|| toml::Value::String(value.to_owned()));
    let keys: Vec<&str> = path.trim().split('.').collect();
    let mut node = doc;
    let mut i = 0;
    while i < keys.len() {
        let k = keys[i];
        if i + 1 == keys.len() {
            node.insert(k.to_owned(), parsed);
            return Ok(());
        }
        let entry = node
            .entry(k.to_owned())
            .or_insert_with(|| toml::Value::Table(toml::Table::new()));
        i += 1;
        node = match entry {
            toml::Value::Table(t) => t,
            // An array of tables ([[contact]]): the only one, or the one the
            // next key names by index (dirichlet.2.value).
            toml::Value::Array(a) => {
                let index = match keys[i].parse::<usize>() {
                    Ok(n) if i + 1 < keys.len() => {
                        i += 1;
                        n
                    }
                    _ if a.len() == 1 => 0,
                    _ => {
                        return Err(format!(
                            "'{k}' has {} entries: name one as {k}.N.key (N from 0)",
                            a.len()
                        ))
                    }
                };
                let len = a.len();
                match a.get_mut(index) {
                    Some(toml::Value::Table(t)) => t,
                    _ => return Err(format!("'{k}' has no table entry {index} (it has {len})")),
                }
            }
            _ => return Err(format!("'{k}' is not a table")),
        };
    }
    Err("empty key".into())
}

/// A semantic scene error and the key it is about (an absolute key path;
/// empty: the section the caller names), so the message can give its line.
#[derive(Debug)]
pub(super) struct Bad {
    pub(super) path: Vec<Seg>,
    pub(super) message: String,
}

impl Bad {
    pub(super) fn at(path: &[Seg], message: impl Into<String>) -> Self {
        Bad {
            path: path.to_vec(),
            message: message.into(),
        }
    }
}

impl From<String> for Bad {
    fn from(message: String) -> Self {
        Bad {
            path: Vec::new(),
            message,
        }
    }
}

impl From<&str> for Bad {
    fn from(message: &str) -> Self {
        message.to_owned().into()
    }
}

pub(super) type Checked<T> = std::result::Result<T, Bad>;

/// `origin` with a line: `path:14` for a file, `..., line 14` for a built-in.
pub(super) fn with_line(origin: &str, line: usize) -> String {
    if origin.starts_with("built-in") {
        format!("{origin}, line {line}")
    } else {
        format!("{origin}:{line}")
    }
}

impl Scene {
    /// An error about the key at `path`: names its line in the scene file,
    /// or the `--set` override that supplied it.
    pub fn error_at(&self, origin: &str, path: &[Seg], message: impl Into<String>) -> Error {
        let message = message.into();
        match self.lines.locate(path) {
            Origin::Line(n) => Error::scene(with_line(origin, n), message),
            Origin::Override(o) => Error::scene(origin, format!("--set {o}: {message}")),
            Origin::Unknown => Error::scene(origin, message),
        }
    }

    /// Turns a [`Bad`] into an error at its key, or at `section` when it
    /// names none.
    pub(super) fn located<'a>(
        &'a self,
        origin: &'a str,
        section: &'a [Seg],
    ) -> impl Fn(Bad) -> Error + 'a {
        move |b| {
            let path = if b.path.is_empty() { section } else { &b.path };
            self.error_at(origin, path, b.message)
        }
    }
}
