// Leaf outlines (Weber-Penn LeafShape) for the renderer's fragment test. Twin:
// sylva_core::model::leaf_shape (leaf_radius, LeafShape::contains, disc_half_width): same
// operations in the same order. The leaf mesher's rims come from a table made on the CPU
// (MeshLayout::leaf_rim_table).

const LEAF_PI: f32 = 3.141592653589793;
const LEAF_TAU: f32 = 6.283185307179586;

fn leaf_ellipse(a: f32, b: f32, theta: f32) -> f32 {
    let s = sin(theta) / a;
    let c = cos(theta) / b;
    return 1.0 / sqrt(s * s + c * c);
}

// Distance from the leaf square's centre to the outline at theta (from the tip toward +u).
fn leaf_radius(shape: u32, theta: f32) -> f32 {
    let s = sin(theta);
    let c = cos(theta);
    switch shape {
        case 1u: {
            return 0.4 * (1.0 + 0.15 * cos(3.0 * theta));
        }
        case 2u: {
            return leaf_ellipse(0.22, 0.49, theta);
        }
        case 3u: {
            return leaf_ellipse(0.47, 0.49, theta);
        }
        case 4u: {
            return 0.47 / pow(pow(abs(s), 6.0) + pow(abs(c), 6.0), 1.0 / 6.0);
        }
        case 5u: {
            return leaf_ellipse(0.16, 0.49, theta) * (0.72 + 0.28 * abs(cos(14.0 * theta)));
        }
        case 6u: {
            return leaf_ellipse(0.05, 0.49, theta);
        }
        case 7u: {
            return 0.48 * (0.5 + 0.5 * sqrt(abs(cos(2.5 * theta))));
        }
        case 8u: {
            let drop = pow(abs(cos(0.5 * theta)), 10.0);
            let notch = pow(max(-c, 0.0), 12.0);
            return 0.5 * (0.6 + 0.4 * drop - 0.4 * notch);
        }
        default: {
            return 0.5;
        }
    }
}

// (v clamped to the square; the guards keep pow's arguments positive.)
fn leaf_disc_half_width(v_in: f32) -> f32 {
    let v = clamp(v_in, 0.0, 1.0);
    return 0.46 * pow(max(sin(3.14159265 * pow(max(v, 1e-6), 0.75)), 1e-6), 0.9) * pow(max(1.0 - v, 1e-6), 0.15);
}

// Whether (u, v) lies on a blade of this shape.
fn inside_leaf_shape(shape: u32, uv: vec2<f32>) -> bool {
    if (shape == 0u) {
        return abs(uv.x - 0.5) <= leaf_disc_half_width(uv.y);
    }
    let d = uv - vec2<f32>(0.5, 0.5);
    return length(d) <= leaf_radius(shape, atan2(d.x, d.y));
}
