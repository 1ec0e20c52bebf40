//! Parametric, stochastic L-systems with a 3-D turtle (Song §3; Prusinkiewicz &
//! Lindenmayer, *The Algorithmic Beauty of Plants* (ABOP), ch. 1–2).
//!
//! # Grammar files (`.lsys`)
//!
//! One statement per line; `#` or `//` start a comment. Whitespace inside module strings is
//! ignored.
//!
//! ```text
//! name: Monopodial tree (ABOP Fig. 2.6a)
//! iterations: 10          # derivation steps (the CLI's --iterations overrides)
//! angle: 45               # default turn angle for + - & ^ \ / without a parameter, degrees
//! step: 1                 # default length of F and f without a parameter
//! width: 1                # initial width (diameter) before any !(w)
//! scale: 1.5              # metres per unit of length
//! width-scale: 0.03       # metres of diameter per unit of width
//! tropism: 0 -1 0 0.22    # tropism vector T (x y z, +Y up) and susceptibility e (ABOP eq. 2.?)
//! leaf: 0.3 0.15          # default leaf length and width for ~ without parameters, metres
//! define r1 = 0.9         # a named constant (may use earlier constants)
//! axiom: A(1,10)
//! A(l,w) : * -> !(w)F(l)[&(45)B(l*r2,w*wr)]/(137.5)A(l*r1,w*wr)
//! B(l,w) : l > 0.1 ->(0.6) !(w)F(l)[-(45)$C(l*r2,w*wr)]C(l*r1,w*wr)
//! ```
//!
//! A production is `predecessor [: condition] -> [(probability)] successor`. The
//! predecessor is one symbol with formal parameter names; it matches modules with the same
//! symbol and number of parameters whose condition (an expression, `*` = always) holds.
//! Among the productions that match a module, those with probabilities are chosen at random
//! in proportion to them (a production without one weighs 1); if none has a probability,
//! the first in file order applies. Modules no production matches are copied.
//!
//! # Turtle alphabet
//!
//! `F(l)` draw a segment, `f(l)` move without drawing, `+(a)`/`-(a)` turn left/right,
//! `&(a)`/`^(a)` pitch down/up, `\(a)`/`/(a)` roll left/right, `|` turn around,
//! `$` roll so the turtle's left is horizontal, `[`/`]` push/pop the turtle,
//! `!(w)` set the width (diameter), `~(l, w)` a leaf of length `l` and width `w`.
//! Rotations follow ABOP's matrices R_U, R_L, R_H (§1.5). Every other symbol draws nothing.
//!
//! # Stems and levels
//!
//! Consecutive `F`s form one stem; an `F` after `[` starts a child stem one level deeper,
//! attached where the turtle stands on its parent. After `f` the turtle leaves the tree:
//! the next `F` starts a new root stem.
//!
//! # Determinism
//!
//! A stochastic choice is drawn from a hash of (seed, derivation step, module index), so
//! the string — and the tree — is the same whatever the number of threads that rewrite it.

mod derive;
pub(crate) mod expr;
mod parse;
mod turtle;

pub use derive::{LString, Module, Piece};
pub use expr::Expr;

use crate::limits::{LimitExceeded, Limits};
use crate::model::{ModelError, Tree, WoodProperties};
use glam::DVec3;
use std::path::Path;

/// A parse or load error in a grammar file: names the file, line, column and what was
/// expected.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
pub enum GrammarError {
    /// Unexpected text.
    #[error("{file}:{line}:{column}: expected {expected}, found {found}")]
    Syntax { file: String, line: usize, column: usize, expected: String, found: String },
    /// A value is out of its range.
    #[error("{file}:{line}: `{field}`: {message}")]
    Value { file: String, line: usize, field: String, message: String },
    /// A parser limit was hit.
    #[error("{file}:{line}:{column}: limit `{limit}` = {value} exceeded (raise it with --{})", limit.replace('_', "-"))]
    Limit { file: String, line: usize, column: usize, limit: &'static str, value: usize },
    /// The file could not be read.
    #[error("{file}: {message}")]
    Io { file: String, message: String },
}

/// Errors from deriving or interpreting an L-system.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
pub enum LSystemError {
    /// The grammar could not be parsed.
    #[error(transparent)]
    Grammar(#[from] GrammarError),
    /// A size limit would have been exceeded.
    #[error("{file}: {source}")]
    Limit { file: String, source: LimitExceeded },
    /// The turtle met something it cannot draw.
    #[error("{file}: turtle, module {module} (`{symbol}`): {message}")]
    Turtle { file: String, module: usize, symbol: char, message: String },
    /// The turtle drew no segment: there is no tree to build.
    #[error("{file}: the derived string draws no segment (no `F` reached the turtle); a tree needs at least one")]
    NoSegments { file: String },
    /// The resulting tree broke a model invariant.
    #[error("{file}: {source}")]
    Model { file: String, source: ModelError },
}

/// One production `pred(params) : cond -> (prob) successor`.
#[derive(Debug, Clone, PartialEq)]
pub struct Production {
    /// Predecessor symbol.
    pub pred: u8,
    /// Number of formal parameters.
    pub arity: usize,
    /// Condition; `None` means always.
    pub cond: Option<Expr>,
    /// Probability weight of a stochastic production.
    pub prob: Option<f64>,
    /// Successor modules: symbol and parameter expressions.
    pub succ: Vec<(u8, Vec<Expr>)>,
    /// Line in the grammar file.
    pub line: usize,
}

/// A parsed grammar with its turtle settings.
#[derive(Debug, Clone, PartialEq)]
pub struct Grammar {
    /// Display name.
    pub name: String,
    /// File it was read from (for messages).
    pub file: String,
    /// Derivation steps.
    pub iterations: u32,
    /// Default turn angle, degrees.
    pub angle: f64,
    /// Default F/f length, grammar units.
    pub step: f64,
    /// Initial width, grammar width units.
    pub width: f64,
    /// Metres per length unit.
    pub scale: f64,
    /// Metres of diameter per width unit.
    pub width_scale: f64,
    /// Tropism vector and susceptibility e.
    pub tropism: Option<(DVec3, f64)>,
    /// Default leaf length and width, m.
    pub leaf: (f64, f64),
    /// Wood properties for mass and stiffness.
    pub wood: WoodProperties,
    /// Axiom modules with constant parameters.
    pub axiom: Vec<(u8, Vec<f64>)>,
    /// Productions in file order.
    pub productions: Vec<Production>,
}

/// Options for one derivation.
#[derive(Debug, Clone, Copy, Default)]
pub struct LSystemOptions {
    /// Seed of the stochastic choices.
    pub seed: u64,
    /// Overrides the grammar's `iterations`.
    pub iterations: Option<u32>,
    /// Size limits.
    pub limits: Limits,
}

impl Grammar {
    /// Parses grammar text; `file` names it in error messages.
    pub fn parse(text: &str, file: &str) -> Result<Self, GrammarError> {
        parse::parse(text, file, &Limits::default())
    }

    /// Parses with explicit limits.
    pub fn parse_with_limits(text: &str, file: &str, limits: &Limits) -> Result<Self, GrammarError> {
        parse::parse(text, file, limits)
    }

    /// Reads and parses a grammar file (at most 1 MiB).
    pub fn load(path: &Path) -> Result<Self, GrammarError> {
        let file = path.display().to_string();
        let text = crate::io::read_text(path).map_err(|message| GrammarError::Io { file: file.clone(), message })?;
        Self::parse(&text, &file)
    }

    /// Derives the string for the given options.
    pub fn derive(&self, opts: &LSystemOptions) -> Result<LString, LSystemError> {
        derive::derive(self, opts)
    }

    /// Derives and interprets: the tree this grammar grows.
    pub fn generate(&self, opts: &LSystemOptions) -> Result<Tree, LSystemError> {
        let s = self.derive(opts)?;
        let builder = turtle::interpret(self, &s, &opts.limits)?;
        drop(s);
        if builder.segments.is_empty() {
            return Err(LSystemError::NoSegments { file: self.file.clone() });
        }
        builder
            .build(&self.name, opts.seed, self.wood)
            .map_err(|source| LSystemError::Model { file: self.file.clone(), source })
    }
}
