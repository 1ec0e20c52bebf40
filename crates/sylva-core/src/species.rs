//! Species presets shipped with Sylva (`presets/`), and loading of user files.
//!
//! A species argument is either a preset name (`quaking_aspen`, `monopodial`), a Weber–Penn
//! TOML file (`*.toml`) or an L-system grammar file (any other extension, usually `.lsys`).

use crate::generate::lsystem::{Grammar, GrammarError, LSystemError, LSystemOptions};
use crate::generate::weber_penn::{WeberPennError, WeberPennParams};
use crate::limits::Limits;
use crate::model::Tree;
use std::path::Path;

/// Largest preset or grammar file read, bytes.
pub const MAX_FILE_BYTES: u64 = 1 << 20;

/// What kind of generator a preset drives.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum PresetKind {
    /// A Weber–Penn species (TOML).
    Species,
    /// An L-system grammar.
    Grammar,
}

/// A preset shipped in the binary.
#[derive(Debug, Clone, Copy)]
pub struct Preset {
    /// Name used on the command line.
    pub name: &'static str,
    /// Generator kind.
    pub kind: PresetKind,
    /// File name under `presets/`.
    pub file: &'static str,
    /// File contents.
    pub text: &'static str,
}

macro_rules! species {
    ($name:literal) => {
        Preset {
            name: $name,
            kind: PresetKind::Species,
            file: concat!("presets/species/", $name, ".toml"),
            text: include_str!(concat!("../../../presets/species/", $name, ".toml")),
        }
    };
}
macro_rules! grammar {
    ($name:literal) => {
        Preset {
            name: $name,
            kind: PresetKind::Grammar,
            file: concat!("presets/grammars/", $name, ".lsys"),
            text: include_str!(concat!("../../../presets/grammars/", $name, ".lsys")),
        }
    };
}

/// Every shipped preset.
pub const PRESETS: &[Preset] = &[
    species!("quaking_aspen"),
    species!("black_tupelo"),
    species!("ca_black_oak"),
    species!("weeping_willow"),
    species!("sassafras"),
    species!("lombardy_poplar"),
    species!("balsam_fir"),
    species!("palm"),
    grammar!("monopodial"),
    grammar!("sympodial"),
    grammar!("ternary"),
    grammar!("stochastic_bush"),
];

/// The species used when none is named.
pub const DEFAULT_SPECIES: &str = "quaking_aspen";

/// Errors resolving or loading a species.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
pub enum SpeciesError {
    /// Neither a preset nor an existing file.
    #[error("no preset or file named `{name}`; presets: {available}")]
    NotFound { name: String, available: String },
    /// The file could not be read.
    #[error("{file}: {message}")]
    Io { file: String, message: String },
    /// TOML syntax, a missing key, an unknown key or a wrong type.
    #[error("{file}:{line}:{column}: {message}")]
    Toml { file: String, line: usize, column: usize, message: String },
    /// A value out of range.
    #[error("{file}:{line}: `{field}`: {message}")]
    Field { file: String, line: usize, field: String, message: String },
    /// A grammar error.
    #[error(transparent)]
    Grammar(#[from] GrammarError),
    /// An L-system derivation or interpretation error.
    #[error(transparent)]
    LSystem(#[from] LSystemError),
    /// A Weber–Penn generation error.
    #[error("{file}: {source}")]
    WeberPenn { file: String, source: WeberPennError },
}

/// Reads a text file of at most [`MAX_FILE_BYTES`].
pub fn read_text(path: &Path) -> Result<String, String> {
    let meta = std::fs::metadata(path).map_err(|e| e.to_string())?;
    if meta.len() > MAX_FILE_BYTES {
        return Err(format!(
            "file is {} bytes, larger than the {} byte limit for presets and grammars",
            meta.len(),
            MAX_FILE_BYTES
        ));
    }
    std::fs::read_to_string(path).map_err(|e| e.to_string())
}

/// A resolved species: what to generate.
#[derive(Debug, Clone, PartialEq)]
pub enum SpeciesSource {
    /// Weber–Penn parameters, with the file they came from.
    WeberPenn { file: String, params: Box<WeberPennParams> },
    /// An L-system grammar.
    LSystem(Box<Grammar>),
}

/// 1-based line and column of a byte offset.
pub(crate) fn line_col(text: &str, offset: usize) -> (usize, usize) {
    let before = &text[..offset.min(text.len())];
    let line = before.matches('\n').count() + 1;
    let col = before.rfind('\n').map_or(before.len(), |i| before.len() - i - 1) + 1;
    (line, col)
}

/// Line where a dotted field is set in a TOML file: `name[i].key` in the i-th `[[name]]`
/// table (`level[1].length`), `name.key` in `[name]` (`wood.density`, `output.fps`), `key` at
/// the top. The line of the table when the key is absent; 1 when nothing matches (best
/// effort, for error messages).
pub(crate) fn field_line(text: &str, field: &str) -> usize {
    let (table, index, key) = match field.split_once('.') {
        Some((t, k)) => match t.split_once('[') {
            Some((name, rest)) => (format!("[[{name}]]"), rest.trim_end_matches(']').parse::<usize>().ok(), k),
            None => (format!("[{t}]"), None, k),
        },
        None => (String::new(), None, field),
    };
    let key = key.split('[').next().unwrap_or(key);
    let mut in_table = table.is_empty();
    let mut seen = 0usize;
    let mut table_line = 1;
    for (i, line) in text.lines().enumerate() {
        let t = line.trim();
        if t.starts_with('[') {
            in_table = false;
            if !table.is_empty() && t.starts_with(&table) {
                if index.is_none_or(|n| n == seen) {
                    in_table = true;
                    table_line = i + 1;
                }
                seen += 1;
            }
            continue;
        }
        if in_table && t.strip_prefix(key).is_some_and(|r| r.trim_start().starts_with('=')) {
            return i + 1;
        }
    }
    table_line
}

impl SpeciesSource {
    /// Parses Weber–Penn TOML text; `file` names it in errors.
    pub fn parse_species(text: &str, file: &str) -> Result<WeberPennParams, SpeciesError> {
        let params: WeberPennParams = toml::from_str(text).map_err(|e| {
            let (line, column) = e.span().map_or((1, 1), |s| line_col(text, s.start));
            SpeciesError::Toml { file: file.to_string(), line, column, message: e.message().trim().to_string() }
        })?;
        params.check().map_err(|e| SpeciesError::Field {
            file: file.to_string(),
            line: field_line(text, &e.field),
            field: e.field,
            message: e.message,
        })?;
        Ok(params)
    }

    /// Resolves a preset name or a file path.
    pub fn resolve(arg: &str) -> Result<Self, SpeciesError> {
        if let Some(p) = PRESETS.iter().find(|p| p.name == arg) {
            return Self::from_preset(p);
        }
        let path = Path::new(arg);
        if path.exists() {
            let text = read_text(path).map_err(|message| SpeciesError::Io { file: arg.to_string(), message })?;
            return Self::from_text(&text, arg);
        }
        Err(SpeciesError::NotFound {
            name: arg.to_string(),
            available: PRESETS.iter().map(|p| p.name).collect::<Vec<_>>().join(", "),
        })
    }

    /// A shipped preset.
    pub fn from_preset(p: &Preset) -> Result<Self, SpeciesError> {
        match p.kind {
            PresetKind::Species => {
                Ok(Self::WeberPenn { file: p.file.to_string(), params: Box::new(Self::parse_species(p.text, p.file)?) })
            }
            PresetKind::Grammar => Ok(Self::LSystem(Box::new(Grammar::parse(p.text, p.file)?))),
        }
    }

    /// Text of a file: TOML when `file` ends in `.toml`, a grammar otherwise.
    pub fn from_text(text: &str, file: &str) -> Result<Self, SpeciesError> {
        if file.ends_with(".toml") {
            Ok(Self::WeberPenn { file: file.to_string(), params: Box::new(Self::parse_species(text, file)?) })
        } else {
            Ok(Self::LSystem(Box::new(Grammar::parse(text, file)?)))
        }
    }

    /// Display name.
    pub fn name(&self) -> &str {
        match self {
            Self::WeberPenn { params, .. } => &params.name,
            Self::LSystem(g) => &g.name,
        }
    }

    /// Grows the tree. `iterations` overrides a grammar's derivation steps.
    pub fn generate(&self, seed: u64, limits: &Limits, iterations: Option<u32>) -> Result<Tree, SpeciesError> {
        match self {
            Self::WeberPenn { file, params } => {
                params.generate(seed, limits).map_err(|source| SpeciesError::WeberPenn { file: file.clone(), source })
            }
            Self::LSystem(g) => Ok(g.generate(&LSystemOptions { seed, iterations, limits: *limits })?),
        }
    }
}
