//! The generation limits as flags (`--max-segments`, …), shared by every command that grows
//! a tree: the flags that a limit's error message names.

use sylva_core::Limits;

/// Flags for every field of [`Limits`].
#[derive(clap::Args, Debug, Clone)]
pub struct LimitArgs {
    /// Stop with an error before a tree exceeds this many segments.
    #[arg(long, default_value_t = Limits::default().max_segments)]
    pub max_segments: usize,
    /// Stop with an error before a tree exceeds this many leaves.
    #[arg(long, default_value_t = Limits::default().max_leaves)]
    pub max_leaves: usize,
    /// Largest L-system string (modules) during derivation.
    #[arg(long, default_value_t = Limits::default().max_modules)]
    pub max_modules: usize,
    /// Largest number of L-system parameters held during derivation.
    #[arg(long, default_value_t = Limits::default().max_parameters)]
    pub max_parameters: usize,
    /// Largest number of L-system derivation steps.
    #[arg(long, default_value_t = Limits::default().max_iterations)]
    pub max_iterations: u32,
    /// Deepest bracket nesting the turtle follows.
    #[arg(long, default_value_t = Limits::default().max_branch_depth)]
    pub max_branch_depth: usize,
    /// Deepest expression nesting in a grammar.
    #[arg(long, default_value_t = Limits::default().max_expression_depth)]
    pub max_expression_depth: usize,
    /// Largest scene: segments and leaves summed over every tree and its instances.
    #[arg(long, default_value_t = Limits::default().max_scene_elements)]
    pub max_scene_elements: usize,
}

impl Default for LimitArgs {
    fn default() -> Self {
        Self::from(Limits::default())
    }
}

impl From<Limits> for LimitArgs {
    fn from(l: Limits) -> Self {
        Self {
            max_segments: l.max_segments,
            max_leaves: l.max_leaves,
            max_modules: l.max_modules,
            max_parameters: l.max_parameters,
            max_iterations: l.max_iterations,
            max_branch_depth: l.max_branch_depth,
            max_expression_depth: l.max_expression_depth,
            max_scene_elements: l.max_scene_elements,
        }
    }
}

impl LimitArgs {
    /// The limits the flags set.
    pub fn limits(&self) -> Limits {
        Limits {
            max_segments: self.max_segments,
            max_leaves: self.max_leaves,
            max_modules: self.max_modules,
            max_parameters: self.max_parameters,
            max_iterations: self.max_iterations,
            max_branch_depth: self.max_branch_depth,
            max_expression_depth: self.max_expression_depth,
            max_scene_elements: self.max_scene_elements,
        }
    }
}
