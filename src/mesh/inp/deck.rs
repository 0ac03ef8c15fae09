//! The keyword format: lines into keywords with parameters and data lines
//! with fields, comments and blank lines dropped, `*INCLUDE` followed in
//! place. What the keywords mean is `read`'s.

use std::path::{Path, PathBuf};

use super::error::{InpError, InpErrorKind};

/// How deep `*INCLUDE` may nest: deeper is surely a mistake.
const MAX_INCLUDE_DEPTH: usize = 32;

/// Where a line is: the file (an index into the files read) and its line.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub(super) struct Loc {
    pub(super) file: u32,
    pub(super) line: u32,
}

/// An error before it has its file's name: where, and what.
#[derive(Debug, Clone, PartialEq)]
pub(super) struct Fail {
    pub(super) at: Option<Loc>,
    pub(super) kind: InpErrorKind,
}

impl Fail {
    pub(super) fn at(at: Loc, kind: InpErrorKind) -> Self {
        Fail { at: Some(at), kind }
    }

    pub(super) fn whole_file(kind: InpErrorKind) -> Self {
        Fail { at: None, kind }
    }
}

/// A keyword line: the keyword in upper case with single spaces
/// (`CONTACT PAIR`), its parameters (names in upper case, values as written
/// without quotes), and where it is.
#[derive(Debug, Clone, PartialEq)]
pub(super) struct Keyword {
    pub(super) name: String,
    pub(super) params: Vec<(String, Option<String>)>,
    pub(super) at: Loc,
}

impl Keyword {
    /// The value of parameter `name`, if given with one.
    pub(super) fn value(&self, name: &str) -> Option<&str> {
        self.params
            .iter()
            .find(|(n, _)| n == name)
            .and_then(|(_, v)| v.as_deref())
    }

    /// Whether parameter `name` is given (with or without a value).
    pub(super) fn has(&self, name: &str) -> bool {
        self.params.iter().any(|(n, _)| n == name)
    }

    /// The value of a parameter the keyword needs.
    pub(super) fn require(&self, name: &'static str) -> Result<&str, Fail> {
        self.value(name).filter(|v| !v.is_empty()).ok_or_else(|| {
            let kind = InpErrorKind::MissingParameter {
                keyword: self.name.clone(),
                parameter: name,
            };
            Fail::at(self.at, kind)
        })
    }

    /// The parameters not in `known`, which the reader does not read (the
    /// caller lists them in the note); `INSTANCE` (a file with parts) and
    /// `INPUT` (data lines in another file) are errors: what they change
    /// would be missed.
    pub(super) fn unknown_params(&self, known: &[&str]) -> Result<Vec<&str>, Fail> {
        let mut unknown = Vec::new();
        for (name, _) in &self.params {
            match name.as_str() {
                n if known.contains(&n) => {}
                "INSTANCE" => {
                    return Err(Fail::at(self.at, InpErrorKind::Parts(self.name.clone())))
                }
                "INPUT" => {
                    let kind = InpErrorKind::DataElsewhere(self.name.clone());
                    return Err(Fail::at(self.at, kind));
                }
                n => unknown.push(n),
            }
        }
        Ok(unknown)
    }
}

/// A data line: its comma-separated fields, trimmed (a trailing empty field
/// dropped, and then `continued` is set), and where it is.
pub(super) struct DataLine<'a> {
    pub(super) fields: &'a [&'a str],
    pub(super) continued: bool,
    pub(super) text: &'a str,
    pub(super) at: Loc,
}

/// What the keywords and data lines go to, in file order (includes in place).
pub(super) trait Handler {
    fn keyword(&mut self, keyword: Keyword) -> Result<(), Fail>;
    fn data(&mut self, line: &DataLine) -> Result<(), Fail>;
}

/// Reads a file and its includes, and names the files in messages.
pub(super) struct Reader {
    /// Display name of each file read, by `Loc::file`.
    names: Vec<String>,
    /// Path of each file read (the main file's as given).
    paths: Vec<PathBuf>,
    /// Canonical paths of the files being read, outermost first.
    stack: Vec<PathBuf>,
}

impl Reader {
    pub(super) fn new(main: &Path) -> Self {
        Reader {
            names: vec![main.display().to_string()],
            paths: vec![main.to_path_buf()],
            stack: vec![main.canonicalize().unwrap_or_else(|_| main.to_path_buf())],
        }
    }

    /// Reads the main file's text.
    pub(super) fn read_main(&mut self, text: &str, h: &mut impl Handler) -> Result<(), Fail> {
        self.read_text(text, 0, h)
    }

    /// The files `*INCLUDE` read, each once.
    pub(super) fn included(&self) -> Vec<PathBuf> {
        let mut files: Vec<PathBuf> = Vec::new();
        for p in self.paths.iter().skip(1) {
            if !files.contains(p) {
                files.push(p.clone());
            }
        }
        files
    }

    /// `line 12`, or `mat.inp, line 3` in an included file.
    pub(super) fn place(&self, at: Loc) -> String {
        let file = at.file as usize;
        match self.paths.get(file) {
            Some(p) if file > 0 => {
                let name = p.file_name().map_or(p.as_os_str(), |n| n);
                format!("{}, line {}", name.to_string_lossy(), at.line)
            }
            _ => format!("line {}", at.line),
        }
    }

    /// The error with its file's name.
    pub(super) fn error(&self, fail: Fail) -> InpError {
        let file = fail.at.map_or(0, |at| at.file as usize);
        InpError {
            file: self.names.get(file).cloned().unwrap_or_default(),
            line: fail.at.map(|at| at.line as usize),
            kind: fail.kind,
        }
    }

    fn read_text(&mut self, text: &str, file: u32, h: &mut impl Handler) -> Result<(), Fail> {
        let mut lines = text.lines().enumerate().filter_map(|(i, raw)| {
            let line = raw.trim();
            let skip = line.is_empty() || line.starts_with("**");
            let number = u32::try_from(i + 1).unwrap_or(u32::MAX);
            (!skip).then_some((Loc { file, line: number }, line))
        });
        let mut fields: Vec<&str> = Vec::new();
        while let Some((at, line)) = lines.next() {
            if line.starts_with('*') {
                let mut text = line.to_string();
                // A keyword line ending in a comma continues on the next.
                while text.ends_with(',') {
                    match lines.next() {
                        Some((_, more)) if !more.starts_with('*') => text.push_str(more),
                        Some((next, more)) => {
                            let shown = shorten(more);
                            return Err(Fail::at(next, InpErrorKind::BadKeyword(shown)));
                        }
                        None => break,
                    }
                }
                let keyword = parse_keyword(&text, at)?;
                if keyword.name == "INCLUDE" {
                    self.include(&keyword, h)?;
                } else {
                    h.keyword(keyword)?;
                }
                continue;
            }
            fields.clear();
            fields.extend(line.split(',').map(str::trim));
            let continued = fields.len() > 1 && fields.last() == Some(&"");
            if continued {
                fields.pop();
            }
            let data = DataLine {
                fields: &fields,
                continued,
                text: line,
                at,
            };
            h.data(&data)?;
        }
        Ok(())
    }

    /// Reads the file an `*INCLUDE` names, relative to the including file.
    fn include(&mut self, keyword: &Keyword, h: &mut impl Handler) -> Result<(), Fail> {
        let input = keyword.require("INPUT")?;
        let from = keyword.at.file as usize;
        let dir = self
            .paths
            .get(from)
            .and_then(|p| p.parent())
            .map(Path::to_path_buf)
            .unwrap_or_default();
        let path = dir.join(input);
        let failed = |reason: String| {
            let path = path.display().to_string();
            Fail::at(keyword.at, InpErrorKind::Include { path, reason })
        };
        let bytes = read_file(&path).map_err(|e| failed(e.to_string()))?;
        let canonical = path.canonicalize().map_err(|e| failed(e.to_string()))?;
        if self.stack.contains(&canonical) {
            let chain: Vec<String> = self
                .stack
                .iter()
                .chain(std::iter::once(&canonical))
                .map(|p| p.display().to_string())
                .collect();
            let kind = InpErrorKind::IncludeCycle(chain.join(" → "));
            return Err(Fail::at(keyword.at, kind));
        }
        if self.stack.len() >= MAX_INCLUDE_DEPTH {
            let kind = InpErrorKind::IncludeDepth(MAX_INCLUDE_DEPTH);
            return Err(Fail::at(keyword.at, kind));
        }
        let file = u32::try_from(self.paths.len()).unwrap_or(u32::MAX);
        self.names.push(path.display().to_string());
        self.paths.push(path);
        self.stack.push(canonical);
        let read = self.read_text(&String::from_utf8_lossy(&bytes), file, h);
        self.stack.pop();
        read
    }
}

/// The bytes of a regular file: a device or a pipe (`/dev/zero`) could
/// never end.
pub(super) fn read_file(path: &Path) -> std::io::Result<Vec<u8>> {
    if !std::fs::metadata(path)?.is_file() {
        return Err(std::io::Error::other("not a regular file"));
    }
    std::fs::read(path)
}

/// `*NAME, P1=V1, FLAG`: the name in upper case with single spaces, the
/// parameter names in upper case, values trimmed and unquoted.
pub(super) fn parse_keyword(text: &str, at: Loc) -> Result<Keyword, Fail> {
    let body = text.strip_prefix('*').unwrap_or(text);
    let mut parts = body.split(',');
    let name = parts
        .next()
        .unwrap_or_default()
        .split_whitespace()
        .collect::<Vec<_>>()
        .join(" ")
        .to_uppercase();
    if name.is_empty() {
        return Err(Fail::at(at, InpErrorKind::BadKeyword(shorten(text))));
    }
    let mut params = Vec::new();
    for part in parts.map(str::trim).filter(|p| !p.is_empty()) {
        let (key, value) = match part.split_once('=') {
            Some((k, v)) => (k.trim(), Some(unquote(v.trim()).to_string())),
            None => (part, None),
        };
        if key.is_empty() {
            return Err(Fail::at(at, InpErrorKind::BadKeyword(shorten(text))));
        }
        let key = key.split_whitespace().collect::<Vec<_>>().join(" ");
        params.push((key.to_uppercase(), value));
    }
    Ok(Keyword { name, params, at })
}

/// A name without the double quotes Abaqus allows around it.
pub(super) fn unquote(s: &str) -> &str {
    s.strip_prefix('"')
        .and_then(|t| t.strip_suffix('"'))
        .unwrap_or(s)
}

/// A piece of the file for a message: at most 60 characters.
pub(super) fn shorten(s: &str) -> String {
    let mut out: String = s.chars().take(60).collect();
    if s.chars().nth(60).is_some() {
        out.push_str("...");
    }
    out
}
