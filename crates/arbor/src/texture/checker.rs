//! The 3D checkerboard of CENG 795 hw4: the parities of the integer parts of `(p + offset) · scale`
//! along x, y and z (truncated towards zero, as C's `(int)` cast) pick black when their exclusive or is
//! odd.

use crate::math::{Color, Vec3};

/// A checkerboard of two colours.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Checkerboard {
    /// Squares per unit.
    pub scale: f32,
    /// Added to the point before scaling.
    pub offset: f32,
    /// The odd squares.
    pub black: Color,
    /// The even squares.
    pub white: Color,
}

impl Checkerboard {
    /// The colour at `p`.
    pub fn eval(&self, p: Vec3) -> Color {
        let odd = |c: f32| ((c + self.offset) * self.scale) as i64 % 2 != 0;
        if (odd(p.x) != odd(p.y)) != odd(p.z) {
            self.black
        } else {
            self.white
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn checkerboard_alternates_and_truncates_towards_zero() {
        let c = Checkerboard { scale: 1.0, offset: 0.0, black: Color::ZERO, white: Color::ONE };
        assert_eq!(c.eval(Vec3::new(0.5, 0.5, 0.5)), Color::ONE);
        assert_eq!(c.eval(Vec3::new(1.5, 0.5, 0.5)), Color::ZERO);
        assert_eq!(c.eval(Vec3::new(1.5, 1.5, 0.5)), Color::ONE);
        assert_eq!(c.eval(Vec3::new(1.5, 1.5, 1.5)), Color::ZERO);
        // (int)(-0.5) is 0, like (int)(0.5): the square at the origin spans [-1, 1).
        assert_eq!(c.eval(Vec3::new(-0.5, 0.5, 0.5)), Color::ONE);
        assert_eq!(c.eval(Vec3::new(-1.5, 0.5, 0.5)), Color::ZERO);
    }
}
