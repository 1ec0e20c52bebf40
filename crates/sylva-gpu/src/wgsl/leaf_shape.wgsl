// Leaf outlines (Weber-Penn LeafShape), shared by the leaf mesher and the renderer. Twin:
// sylva_core::model::leaf_shape (leaf_radius, leaf_rim, LeafShape::contains, disc_half_width):
// same operations in the same order.

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

// Half-extents (across, along) of the polar outlines (leaf_box in leaf_shape.rs).
fn leaf_box(shape: u32) -> vec2<f32> {
    switch shape {
        case 1u: {
            return vec2<f32>(0.42, 0.48);
        }
        case 2u: {
            return vec2<f32>(0.22, 0.49);
        }
        case 3u: {
            return vec2<f32>(0.47, 0.49);
        }
        case 4u: {
            return vec2<f32>(0.47, 0.47);
        }
        case 5u: {
            return vec2<f32>(0.16, 0.49);
        }
        case 6u: {
            return vec2<f32>(0.05, 0.49);
        }
        case 7u: {
            return vec2<f32>(0.48, 0.48);
        }
        case 8u: {
            return vec2<f32>(0.33, 0.5);
        }
        default: {
            return vec2<f32>(0.5, 0.5);
        }
    }
}

// Rim vertex k of `sides` of a leaf polygon, (u, v): the disc's ellipse, or a polygon that
// holds a polar outline (leaf_rim in leaf_shape.rs: 16 samples a sector, 2 % margin).
fn leaf_rim(shape: u32, k: u32, sides: u32) -> vec2<f32> {
    let step = LEAF_TAU / f32(sides);
    let a = LEAF_TAU * f32(k) / f32(sides);
    if (shape == 0u) {
        let rd = 0.5 / cos(0.5 * step);
        return vec2<f32>(0.5 + rd * sin(a), 0.5 - rd * cos(a));
    }
    let b = leaf_box(shape);
    let alpha = LEAF_PI - a;
    var r = 0.0;
    for (var j = 0u; j <= 32u; j++) {
        let off = step * (f32(j) / 16.0 - 1.0);
        let phi = alpha + off;
        let theta = atan2(b.x * sin(phi), b.y * cos(phi));
        let rr = leaf_radius(shape, theta);
        let x = rr * sin(theta) / b.x;
        let y = rr * cos(theta) / b.y;
        r = max(r, sqrt(x * x + y * y) * cos(abs(off) - 0.5 * step));
    }
    r = r * 1.02 / cos(0.5 * step);
    return vec2<f32>(0.5 + b.x * r * sin(alpha), 0.5 + b.y * r * cos(alpha));
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
