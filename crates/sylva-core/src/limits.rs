//! Size and recursion limits that keep user input from exhausting memory or time.
//!
//! Every generator checks these while it grows a tree, so a grammar or preset that would
//! exceed a limit stops with [`LimitExceeded`] naming the limit *before* memory grows past it.

use std::fmt;

/// Limits applied while generating a tree. The defaults suit a desktop machine.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct Limits {
    /// Largest number of branch segments in one tree. Default 5 million (≈ 0.5 GB of
    /// model arrays), well above the largest tree in the papers' tables (Song Table 2:
    /// 4,975 clusters; Akagi Table 2: 4.1 M polygons).
    pub max_segments: usize,
    /// Largest number of leaves in one tree. Default 10 million.
    pub max_leaves: usize,
    /// Largest L-system string (modules) during derivation. Default 50 million (≈ 0.4 GB
    /// of modules plus their parameters).
    pub max_modules: usize,
    /// Largest number of L-system parameters held during derivation. Default 100 million.
    pub max_parameters: usize,
    /// Largest number of derivation steps. Default 1,000.
    pub max_iterations: u32,
    /// Deepest bracket nesting the turtle follows. Default 100,000.
    pub max_branch_depth: usize,
    /// Deepest expression nesting the grammar parser accepts. Default 64.
    pub max_expression_depth: usize,
    /// Largest scene: segments and leaves summed over every tree and each of its instances
    /// (what the per-frame poses, meshes and simulation state grow with, about 1 KiB each).
    /// Default 3 million: about 3 GiB; 64 weeping willows (13.4 million) would take about 13 GB.
    pub max_scene_elements: usize,
}

impl Default for Limits {
    fn default() -> Self {
        Self {
            max_segments: 5_000_000,
            max_leaves: 10_000_000,
            max_modules: 50_000_000,
            max_parameters: 100_000_000,
            max_iterations: 1_000,
            max_branch_depth: 100_000,
            max_expression_depth: 64,
            max_scene_elements: 3_000_000,
        }
    }
}

/// A generator stopped because the tree would exceed one of the [`Limits`].
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct LimitExceeded {
    /// The name of the limit, as in [`Limits`] (e.g. `max_segments`).
    pub limit: &'static str,
    /// The limit's value.
    pub value: usize,
}

impl fmt::Display for LimitExceeded {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        write!(
            f,
            "limit `{}` = {} exceeded; generation stopped before allocating more \
             (raise it with --{} if this tree is intended)",
            self.limit,
            self.value,
            self.limit.replace('_', "-")
        )
    }
}

impl std::error::Error for LimitExceeded {}
