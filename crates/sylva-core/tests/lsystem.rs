//! L-system derivation and turtle interpretation.

use glam::Vec3;
use sylva_core::{Grammar, LSystemOptions, Tree};

fn derive(text: &str, n: u32) -> String {
    let g = Grammar::parse(text, "t.lsys").unwrap();
    g.derive(&LSystemOptions { iterations: Some(n), ..Default::default() }).unwrap().to_text()
}

fn tree(text: &str) -> Tree {
    Grammar::parse(text, "t.lsys").unwrap().generate(&LSystemOptions::default()).unwrap()
}

fn close(a: Vec3, b: Vec3) {
    assert!((a - b).length() < 1e-5, "{a} vs {b}");
}

#[test]
fn algae_grows_by_fibonacci() {
    let g = "axiom: A\nA -> AB\nB -> A\n";
    let lens: Vec<usize> = (0..8).map(|n| derive(g, n).len()).collect();
    assert_eq!(lens, [1, 2, 3, 5, 8, 13, 21, 34]);
    assert_eq!(derive(g, 4), "ABAABABA");
}

#[test]
fn parametric_productions_follow_abop_fig_1_31() {
    let g = "axiom: B(2)A(4,4)\n\
             A(x,y) : y <= 3 -> A(x*2,x+y)\n\
             A(x,y) : y > 3 -> B(x)A(x/y,0)\n\
             B(x) : x < 1 -> C\n\
             B(x) : x >= 1 -> B(x-1)\n";
    assert_eq!(derive(g, 1), "B(1)B(4)A(1,0)");
    assert_eq!(derive(g, 2), "B(0)B(3)A(2,1)");
    assert_eq!(derive(g, 3), "CB(2)A(4,3)");
    assert_eq!(derive(g, 4), "CB(1)A(8,7)");
}

#[test]
fn expressions_follow_precedence_and_functions() {
    let cases = [
        ("2+3*4^2/8-1", 7.0),
        ("max(1,sqrt(16))+abs(-2)", 6.0),
        ("1 + (2 < 3 && 4 >= 4)", 2.0),
        ("sin(30)*2", 1.0),
        ("-2^2 + 5", 1.0),
        ("(1 || 0) + !0 + (3 != 3)", 2.0),
        ("k*2", 3.0),
    ];
    for (e, want) in cases {
        let t = tree(&format!("define j = 0.5\ndefine k = j*3\naxiom: F({e})\n"));
        assert!((t.segments.length[0] - want).abs() < 1e-6, "{e}: {}", t.segments.length[0]);
    }
}

#[test]
fn stochastic_choices_follow_probabilities_and_seed() {
    let axiom = "X".repeat(20_000);
    let text = format!("axiom: {axiom}\nX ->(0.2) A\nX ->(0.8) B\n");
    let g = Grammar::parse(&text, "s.lsys").unwrap();
    let opts = |seed| LSystemOptions { seed, iterations: Some(1), ..Default::default() };
    let s1 = g.derive(&opts(1)).unwrap();
    let a = s1.count(b'A');
    assert_eq!(a + s1.count(b'B'), 20_000);
    // Binomial(20000, 0.2): mean 4000, σ ≈ 57; allow 5σ.
    assert!((a as i64 - 4000).abs() < 285, "{a}");
    assert_eq!(s1, g.derive(&opts(1)).unwrap());
    assert_ne!(s1, g.derive(&opts(2)).unwrap());
    // Conditions filter before the draw.
    let g = Grammar::parse(
        "axiom: X(1)X(5)\nX(n) : n > 3 ->(0.5) A\nX(n) : n > 3 ->(0.5) B\nX(n) : n <= 3 -> C\n",
        "c.lsys",
    )
    .unwrap();
    for seed in 0..20 {
        let s = g.derive(&LSystemOptions { seed, iterations: Some(1), ..Default::default() }).unwrap().to_text();
        assert!(s == "CA" || s == "CB", "{s}");
    }
}

#[test]
fn derivation_is_independent_of_thread_count() {
    let g =
        Grammar::parse("axiom: A(0)\nA(n) ->(0.7) F(1)[+A(n+1)]A(n+1)\nA(n) ->(0.3) F(0.5)A(n+1)\n", "p.lsys").unwrap();
    let opts = LSystemOptions { seed: 9, iterations: Some(20), ..Default::default() };
    let run = |threads| {
        rayon::ThreadPoolBuilder::new().num_threads(threads).build().unwrap().install(|| g.derive(&opts).unwrap())
    };
    let one = run(1);
    assert!(one.len() > 50_000);
    assert_eq!(one, run(3));
}

#[test]
fn turtle_turns_pitches_and_rolls_as_in_abop() {
    // + turns H toward L (= −X at rest).
    let t = tree("angle: 90\naxiom: F+F\n");
    assert_eq!(t.stems.len(), 1);
    close(t.segments.end(1), Vec3::new(-1.0, 1.0, 0.0));
    // & pitches H toward U (= +Z at rest); a bracket starts a child stem one level deeper.
    let t = tree("angle: 90\naxiom: F[&F]F\n");
    assert_eq!(t.stems.len(), 2);
    assert_eq!(t.segments.level, vec![0, 0, 1]);
    close(t.segments.end(2), Vec3::new(0.0, 1.0, 1.0));
    assert_eq!(t.segments.parent[2], 0);
    assert_eq!(t.children.of(0), &[1, 2]);
    // / rolls L toward −U: a following + then turns toward −Z.
    let t = tree("axiom: F/(90)+(90)F\n");
    close(t.segments.end(1), Vec3::new(0.0, 1.0, -1.0));
    // | turns around.
    let t = tree("axiom: F|F\n");
    close(t.segments.end(1), Vec3::new(0.0, 0.0, 0.0));
}

#[test]
fn f_moves_without_drawing_and_starts_a_new_root() {
    let t = tree("axiom: FfF\n");
    assert_eq!(t.stems.len(), 2);
    assert_eq!(t.stems.parent, vec![u32::MAX, u32::MAX]);
    close(t.segments.start[1], Vec3::new(0.0, 2.0, 0.0));
}

#[test]
fn widths_scale_and_leaves_attach() {
    let t = tree("scale: 2\nwidth-scale: 0.01\naxiom: !(2)F!(1)F~(0.5,0.2)\n");
    assert_eq!(t.segments.radius_base, vec![0.01, 0.005]);
    assert_eq!(t.segments.radius_tip, vec![0.005, 0.005]);
    assert_eq!(t.leaves.len(), 1);
    assert_eq!(t.leaves.segment[0], 1);
    close(t.leaves.position[0], Vec3::new(0.0, 4.0, 0.0));
    assert!((t.leaves.length[0] - 1.0).abs() < 1e-6 && (t.leaves.width[0] - 0.4).abs() < 1e-6);
}

#[test]
fn tropism_bends_toward_its_vector() {
    let straight = tree("axiom: &(45)FFFFFF\n");
    let bent = tree("tropism: 0 -1 0 0.3\naxiom: &(45)FFFFFF\n");
    let n = straight.segments.len() - 1;
    assert!(bent.segments.end(n).y < straight.segments.end(n).y - 0.5);
    // No bend where H is parallel to T.
    let up = tree("tropism: 0 1 0 0.5\naxiom: FFF\n");
    close(up.segments.end(2), Vec3::new(0.0, 3.0, 0.0));
}

#[test]
fn dollar_levels_the_turtle() {
    let t = tree("axiom: &(30)/(70)+(20)$F~\n");
    let left = t.leaves.orientation[0] * -Vec3::X;
    assert!(left.y.abs() < 1e-5, "{left}");
    let heading = t.segments.axis(0);
    let before = tree("axiom: &(30)/(70)+(20)F\n").segments.axis(0);
    close(heading, before);
}
