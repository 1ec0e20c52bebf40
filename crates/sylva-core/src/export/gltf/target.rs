//! Export targets: `film` keeps every segment, leaf and float; `game` builds the asset a game
//! engine takes as it is — a skin within a bone budget, levels of detail within triangle
//! budgets (fewer sides, the thinnest twigs left to leaf cards that carry several leaves on
//! one alpha-masked quad) and compact vertex data.

use super::*;
use crate::mesh::meshed_stems;

/// What an export is for.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub enum Target {
    /// A game asset within [`GAME_BUDGET`].
    #[default]
    Game,
    /// Full detail: a joint per segment, every leaf, float data.
    Film,
}

/// What a game export may spend.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Budget {
    /// Joints per skin, leaf joints included. 256: Bevy warns above it and most engines'
    /// GPU skinning indexes bones with a byte.
    pub joints: usize,
    /// Triangles of each level of detail, finest first: 50 k is a hero tree in a current
    /// game; each further level about a third of the one before.
    pub triangles: [usize; 3],
    /// Bytes of a 10 s looping clip at 30 fps with its mesh and textures (10 MiB).
    pub bytes: u64,
}

/// The game target's budget.
pub const GAME_BUDGET: Budget = Budget { joints: 256, triangles: [50_000, 16_000, 5_000], bytes: 10 << 20 };

/// Share of a level's triangles the bark may take; the leaf cards take the rest.
const BARK_SHARE: f32 = 0.5;

/// Tube sides and rings per segment of each game level.
const GAME_TUBES: [(u32, u32); 3] = [(6, 2), (5, 1), (4, 1)];

/// Triangles of the bark at `sides` and `samples` with the stems thinner than `min_radius`
/// left out (no subdivision).
pub fn bark_triangles(tree: &Tree, sides: u32, samples: u32, min_radius: f32) -> usize {
    let meshed = meshed_stems(tree, min_radius);
    let segments: usize =
        (0..tree.stems.len()).filter(|&k| meshed[k]).map(|k| tree.stems.segment_count[k] as usize).sum();
    segments * samples as usize * sides as usize * 2
}

/// The thinnest stem radius whose bark fits `budget` triangles: the smallest stem base radius
/// (the trunk's at most) at which [`bark_triangles`] is within it.
fn min_radius_within(tree: &Tree, sides: u32, samples: u32, budget: usize) -> f32 {
    let s = &tree.segments;
    let mut radii: Vec<f32> = tree.stems.first_segment.iter().map(|&f| s.radius_base[f as usize]).collect();
    radii.sort_by(f32::total_cmp);
    radii.dedup();
    // Triangles fall as the threshold rises: the first radius that fits.
    let k = radii.partition_point(|&r| bark_triangles(tree, sides, samples, r) > budget);
    radii.get(k).copied().unwrap_or_else(|| radii.last().copied().unwrap_or(0.0))
}

/// The game levels of detail of `tree` within `budget`: each level's bark takes at most half
/// its triangles (the thinnest stems dropped until it fits), leaf cards the rest.
pub fn game_lods(tree: &Tree, budget: &Budget) -> Vec<Lod> {
    budget
        .triangles
        .iter()
        .zip(GAME_TUBES)
        .map(|(&total, (sides, samples))| {
            let min_radius = min_radius_within(tree, sides, samples, (total as f32 * BARK_SHARE) as usize);
            let bark = bark_triangles(tree, sides, samples, min_radius);
            let cards = (total.saturating_sub(bark) / CARD_TRIANGLES).max(1);
            let leaf_keep = MeshLayout::leaf_keep_for(cards, tree.leaves.len(), tree.seed);
            Lod { sides, samples, leaf_sides: 4, leaf_keep, min_radius, cards: true, subdivide: false }
        })
        .collect()
}

/// Triangles of one leaf card.
pub const CARD_TRIANGLES: usize = 2;

impl GltfOptions {
    /// The options of `target` for `tree`: [`GltfOptions::film`], or a game asset within
    /// [`GAME_BUDGET`].
    pub fn for_target(target: Target, tree: &Tree) -> Self {
        match target {
            Target::Film => Self::film(),
            Target::Game => Self::game(tree, &GAME_BUDGET),
        }
    }

    /// Full detail: a joint per segment, [`DEFAULT_LODS`], float data, the custom hierarchy
    /// attributes, every key.
    pub fn film() -> Self {
        Self::default()
    }

    /// A game asset of `tree` within `budget`: joints by size within its bone budget, game
    /// levels of detail, quantised data, reduced keys, packed hierarchy only.
    pub fn game(tree: &Tree, budget: &Budget) -> Self {
        Self {
            joints: JointMode::Budget(budget.joints),
            max_joints: Some(budget.joints),
            lods: game_lods(tree, budget),
            leaf_joints: true,
            quantize: true,
            custom_attributes: false,
            key_tolerance_deg: KEY_TOLERANCE_DEG,
            meshopt: false,
            first_lod: 0,
        }
    }
}

/// Key-reduction tolerance of the game target, degrees per joint: 0.05° moves a point
/// 0.87 mm per metre from its pivot, under a pixel at the top of a 20 m tree filling a
/// 1080-pixel-high screen.
pub const KEY_TOLERANCE_DEG: f32 = 0.05;
