//! Species presets shipped with Sylva (`presets/`), and loading of user files.
//!
//! A species argument is either a preset name (`quaking_aspen`, `monopodial`), a Weber–Penn
//! TOML file (`*.toml`) or an L-system grammar file (any other extension, usually `.lsys`).

use crate::generate::lsystem::{Grammar, GrammarError, LSystemError, LSystemOptions};
use crate::generate::weber_penn::{WeberPennError, WeberPennParams};
use crate::io::{field_line, read_text};
use crate::limits::Limits;
use crate::model::Tree;
use std::path::Path;

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

impl Preset {
    /// The preset a name means: its name or its display name (`name` in the file), in any
    /// case, with spaces, hyphens or underscores (`quaking-aspen`, `Quaking Aspen`).
    pub fn find(arg: &str) -> Option<&'static Preset> {
        let key = |s: &str| s.trim().to_lowercase().replace([' ', '-'], "_");
        let wanted = key(arg);
        PRESETS.iter().find(|p| key(p.name) == wanted || key(p.display_name()) == wanted)
    }

    /// The display name written in the file (`name = "Quaking Aspen"` or `name: …`).
    pub fn display_name(&self) -> &'static str {
        self.text
            .lines()
            .find_map(|l| {
                let rest = l.trim_start().strip_prefix("name")?.trim_start();
                let value = rest.strip_prefix('=').or_else(|| rest.strip_prefix(':'))?.trim();
                Some(value.trim_matches('"'))
            })
            .unwrap_or(self.name)
    }
}

/// The species used when none is named.
pub const DEFAULT_SPECIES: &str = "quaking_aspen";

/// Errors resolving or loading a species.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
pub enum SpeciesError {
    /// Neither a preset nor an existing file.
    #[error("no preset or file named `{name}`{looked}; presets: {available}")]
    NotFound {
        /// What was asked for.
        name: String,
        /// Where a path was looked for (` (looked for …)`), empty for a plain name.
        looked: String,
        /// The presets' names.
        available: String,
    },
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

/// A resolved species: what to generate.
#[derive(Debug, Clone, PartialEq)]
pub enum SpeciesSource {
    /// Weber–Penn parameters, with the file they came from.
    WeberPenn { file: String, params: Box<WeberPennParams> },
    /// An L-system grammar.
    LSystem(Box<Grammar>),
}

impl SpeciesSource {
    /// Parses Weber–Penn TOML text; `file` names it in errors.
    pub fn parse_species(text: &str, file: &str) -> Result<WeberPennParams, SpeciesError> {
        let params: WeberPennParams = toml::from_str(text).map_err(|e| {
            let (line, column, message) = crate::io::toml_error(text, &e);
            SpeciesError::Toml { file: file.to_string(), line, column, message }
        })?;
        if let Some((field, written, read)) = crate::io::dropped_elements(text, &params) {
            return Err(SpeciesError::Field {
                file: file.to_string(),
                line: field_line(text, &field),
                field,
                message: format!("{written} elements, expected {read}"),
            });
        }
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
        Self::resolve_with(arg, &Limits::default())
    }

    /// Resolves a preset name or a file path, parsing a grammar within `limits` (its
    /// `iterations` and expression depth).
    pub fn resolve_with(arg: &str, limits: &Limits) -> Result<Self, SpeciesError> {
        if let Some(p) = Preset::find(arg) {
            return Self::from_preset(p);
        }
        let path = Path::new(arg);
        if path.exists() {
            let text = read_text(path).map_err(|message| SpeciesError::Io { file: arg.to_string(), message })?;
            if !arg.ends_with(".toml") {
                return Ok(Self::LSystem(Box::new(Grammar::parse_with_limits(&text, arg, limits)?)));
            }
            return Self::from_text(&text, arg);
        }
        // A shipped preset's path written from elsewhere (`presets/grammars/ternary.lsys`
        // outside the repository) is that preset.
        if let Some(p) = PRESETS.iter().find(|p| arg.ends_with(p.file)) {
            return Self::from_preset(p);
        }
        let looked = if arg.contains(['/', '\\']) || arg.ends_with(".toml") || arg.ends_with(".lsys") {
            let cwd =
                std::env::current_dir().map_or_else(|_| "the working directory".into(), |d| d.display().to_string());
            if path.is_absolute() {
                " (no such file)".to_string()
            } else {
                format!(" (no such file relative to {cwd})")
            }
        } else {
            String::new()
        };
        Err(SpeciesError::NotFound {
            name: arg.to_string(),
            looked,
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
