//! The papers' result tables as published, and the inputs their benchmarks use: what
//! `sylva bench` reproduces row by row.

/// Song's Table 2 (one tree on a GTX 580): clusters, particles, frames per second.
pub const SONG_TABLE_2: [(usize, usize, f64); 7] = [
    (5, 300, 2200.0),
    (15, 900, 1800.0),
    (67, 3444, 1400.0),
    (293, 13548, 1000.0),
    (867, 38772, 670.0),
    (2230, 99816, 350.0),
    (4975, 211812, 175.0),
];

/// Song's Table 3 (ten trees on a GTX 580): clusters, particles, frames per second.
pub const SONG_TABLE_3: [(usize, usize, f64); 7] = [
    (50, 3000, 260.0),
    (150, 9000, 210.0),
    (670, 34440, 160.0),
    (2930, 135480, 110.0),
    (8670, 387720, 70.0),
    (22300, 998160, 36.0),
    (49750, 2118120, 17.0),
];

/// Akagi & Kitajima Table 2 (Core2 Extreme QX9650, GeForce GTX 280): (polygons, CPU
/// single-thread generation + drawing, GPU generation + drawing), seconds per 1,000 frames.
pub const AKAGI_TABLE_2: [(usize, f64, f64); 7] = [
    (108_808, 1.27, 0.006),
    (201_760, 2.58, 0.013),
    (450_592, 6.52, 0.032),
    (823_840, 12.45, 0.064),
    (1_321_504, 20.38, 0.108),
    (2_536_192, 39.79, 0.196),
    (4_109_056, 65.28, 0.352),
];

/// Zioma's Table 6-1 (Intel Xeon 2.33 GHz, GeForce 8800 GTX; 4,617 vertices per
/// instance): (instances, branches, DirectX 9 ms, DirectX 10 SLOD3 ms, DirectX 10 SLOD2 ms,
/// two-bone skinning without branch simulation ms). The table has four data columns under
/// three headings and one pair of sub-headings (SLOD3, SLOD2, the simulation levels of
/// §6.2: trunk and branches, trunk only); the pair is read under DirectX 10, where SLOD2
/// then costs what skinning without branch simulation does (22.48 and 21.61 ms at 1,000
/// instances). `docs/PERFORMANCE.md` gives the other reading and why it was not taken.
pub const ZIOMA_TABLE_6_1: [(usize, usize, f64, f64, f64, f64); 4] = [
    (30, 2_400, 1.46, 1.34, 0.86, 1.39),
    (100, 8_000, 3.90, 3.82, 2.32, 2.22),
    (256, 20_480, 9.81, 9.68, 5.82, 5.59),
    (1_000, 80_000, 38.21, 37.61, 22.48, 21.61),
];

/// Skjermo's results (GeForce 7900 GTX): (branches, updates per second) of the wind
/// animation shader alone, with 256² textures (65,536 branches) and 512² (262,144).
pub const SKJERMO_FIGURE: [(usize, f64); 2] = [(65_536, 600.0), (262_144, 180.0)];

/// The benchmark's L-system (`sylva bench skjermo`, and the generator's million-module
/// benchmark): a binary tree, every stem one segment, two children at ±30° (16 iterations:
/// 65,535 stems; 18: 262,143).
pub const BENCH_BINARY_TREE: &str = "axiom: A(1)\nA(l) -> F(l)[+(30)A(l*0.8)][-(30)/(90)A(l*0.8)]\n";

/// The benchmark's wind, the paper's setting: four sines (eqs. 11–14).
pub const BENCH_FOUR_SINES: &str = "[[field]]\nkind = \"sum_of_sines\"\nsharpness = 2.0\nwaves = [\n\
    { amplitude = 4.0, direction_deg = 0.0, wavelength = 40.0, speed = 6.0 },\n\
    { amplitude = 2.0, direction_deg = 30.0, wavelength = 17.0, speed = 4.0 },\n\
    { amplitude = 1.0, direction_deg = -25.0, wavelength = 9.0, speed = 3.0 },\n\
    { amplitude = 0.5, direction_deg = 60.0, wavelength = 5.0, speed = 2.0 },\n]\n";
