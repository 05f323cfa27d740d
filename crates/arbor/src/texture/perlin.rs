//! Perlin noise, the improved form (Perlin, "Improving Noise", SIGGRAPH 2002): gradients from the
//! twelve cube edge directions picked by a hashed permutation, blended with the quintic fade
//! `6t⁵ - 15t⁴ + 10t³`; zero at lattice points, in [-1, 1]. The texture turns it into [0, 1] by its
//! absolute value or linearly.

use crate::math::Vec3;

/// Ken Perlin's reference permutation of 0..=255.
const PERM: [u8; 256] = [
    151, 160, 137, 91, 90, 15, 131, 13, 201, 95, 96, 53, 194, 233, 7, 225, 140, 36, 103, 30, 69, 142, 8, 99, 37, 240,
    21, 10, 23, 190, 6, 148, 247, 120, 234, 75, 0, 26, 197, 62, 94, 252, 219, 203, 117, 35, 11, 32, 57, 177, 33, 88,
    237, 149, 56, 87, 174, 20, 125, 136, 171, 168, 68, 175, 74, 165, 71, 134, 139, 48, 27, 166, 77, 146, 158, 231, 83,
    111, 229, 122, 60, 211, 133, 230, 220, 105, 92, 41, 55, 46, 245, 40, 244, 102, 143, 54, 65, 25, 63, 161, 1, 216,
    80, 73, 209, 76, 132, 187, 208, 89, 18, 169, 200, 196, 135, 130, 116, 188, 159, 86, 164, 100, 109, 198, 173, 186,
    3, 64, 52, 217, 226, 250, 124, 123, 5, 202, 38, 147, 118, 126, 255, 82, 85, 212, 207, 206, 59, 227, 47, 16, 58, 17,
    182, 189, 28, 42, 223, 183, 170, 213, 119, 248, 152, 2, 44, 154, 163, 70, 221, 153, 101, 155, 167, 43, 172, 9, 129,
    22, 39, 253, 19, 98, 108, 110, 79, 113, 224, 232, 178, 185, 112, 104, 218, 246, 97, 228, 251, 34, 242, 193, 238,
    210, 144, 12, 191, 179, 162, 241, 81, 51, 145, 235, 249, 14, 239, 107, 49, 192, 214, 31, 181, 199, 106, 157, 184,
    84, 204, 176, 115, 121, 50, 45, 127, 4, 150, 254, 138, 236, 205, 93, 222, 114, 67, 29, 24, 72, 243, 141, 128, 195,
    78, 66, 215, 61, 156, 180,
];

#[inline]
fn perm(i: i32) -> i32 {
    PERM[(i & 255) as usize] as i32
}

#[inline]
fn fade(t: f32) -> f32 {
    t * t * t * (t * (t * 6.0 - 15.0) + 10.0)
}

/// The dot product of offset `(x, y, z)` with the edge direction `hash` picks.
#[inline]
fn grad(hash: i32, x: f32, y: f32, z: f32) -> f32 {
    let h = hash & 15;
    let u = if h < 8 { x } else { y };
    let v = if h < 4 {
        y
    } else if h == 12 || h == 14 {
        x
    } else {
        z
    };
    (if h & 1 == 0 { u } else { -u }) + (if h & 2 == 0 { v } else { -v })
}

fn lerp(t: f32, a: f32, b: f32) -> f32 {
    a + t * (b - a)
}

/// Noise at `p`, in [-1, 1].
pub fn noise(p: Vec3) -> f32 {
    let f = p.floor();
    let (xi, yi, zi) = (f.x as i32, f.y as i32, f.z as i32);
    let (x, y, z) = (p.x - f.x, p.y - f.y, p.z - f.z);
    let (u, v, w) = (fade(x), fade(y), fade(z));
    let a = perm(xi) + yi;
    let (aa, ab) = (perm(a) + zi, perm(a + 1) + zi);
    let b = perm(xi + 1) + yi;
    let (ba, bb) = (perm(b) + zi, perm(b + 1) + zi);
    lerp(
        w,
        lerp(
            v,
            lerp(u, grad(perm(aa), x, y, z), grad(perm(ba), x - 1.0, y, z)),
            lerp(u, grad(perm(ab), x, y - 1.0, z), grad(perm(bb), x - 1.0, y - 1.0, z)),
        ),
        lerp(
            v,
            lerp(u, grad(perm(aa + 1), x, y, z - 1.0), grad(perm(ba + 1), x - 1.0, y, z - 1.0)),
            lerp(u, grad(perm(ab + 1), x, y - 1.0, z - 1.0), grad(perm(bb + 1), x - 1.0, y - 1.0, z - 1.0)),
        ),
    )
}

/// The gradient of `noise` at `p`, by central differences.
pub fn gradient(p: Vec3) -> Vec3 {
    const H: f32 = 1e-3;
    let d = |e: Vec3| (noise(p + e) - noise(p - e)) / (2.0 * H);
    Vec3::new(d(Vec3::X * H), d(Vec3::Y * H), d(Vec3::Z * H))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn perlin_table_is_a_permutation() {
        let mut seen = [false; 256];
        PERM.iter().for_each(|&p| seen[p as usize] = true);
        assert!(seen.iter().all(|&s| s));
    }

    #[test]
    fn perlin_is_zero_at_lattice_points() {
        for p in [Vec3::ZERO, Vec3::new(3.0, -2.0, 7.0), Vec3::new(-1.0, 0.0, 255.0)] {
            assert_eq!(noise(p), 0.0);
        }
    }

    #[test]
    fn perlin_matches_a_value_worked_by_hand() {
        // At (0.5, 0, 0) only the corners (0,0,0) and (1,0,0) on the x axis count (y = z = 0 gives
        // fade 0), each weighted 1/2. Corner (0,0,0): hash perm(perm(perm(0)) + 0) = perm(perm(151)) =
        // perm(1) = 160, 160 & 15 = 0: gradient (1, 1, 0) · (0.5, 0, 0) = 0.5. Corner (1,0,0):
        // perm(perm(perm(1))) = perm(perm(160)) = perm(101) = 92, 92 & 15 = 12: x + y = -0.5.
        assert!((noise(Vec3::new(0.5, 0.0, 0.0)) - 0.5 * (0.5 - 0.5)).abs() < 1e-6);
        // At (0.25, 0, 0): fade(0.25) = 0.103515625; 0.25 from the first, -0.75 from the second.
        let t = 0.103_515_625;
        assert!((noise(Vec3::new(0.25, 0.0, 0.0)) - (0.25 + t * (-0.75 - 0.25))).abs() < 1e-6);
    }

    #[test]
    fn perlin_stays_in_range() {
        for i in 0..1000 {
            let p = Vec3::new(i as f32 * 0.377, i as f32 * 0.131 - 20.0, i as f32 * 0.071);
            assert!(noise(p).abs() <= 1.0);
        }
    }
}
