//! Homogeneous transformation matrices and elementary rotations (thesis Appendix A, Eq. 3.18-3.22).
//!
//! An HTM T_{i,j} is stored as a rotation tensor R_{i,j} and the position of the origin of frame j
//! in frame i, so that `p_i = R p_j + t` (Eq. 3.20). Composition follows Eq. 3.22.

use nalgebra::{Matrix3, Vector3};

/// A homogeneous transformation matrix (Eq. 3.18) as (R, p).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Htm {
    pub rotation: Matrix3<f64>,
    pub translation: Vector3<f64>,
}

impl Default for Htm {
    fn default() -> Self {
        Self::identity()
    }
}

impl Htm {
    pub fn identity() -> Self {
        Htm { rotation: Matrix3::identity(), translation: Vector3::zeros() }
    }
    /// T^d(x, y, z), Eq. A.1.
    pub fn displacement(x: f64, y: f64, z: f64) -> Self {
        Htm { rotation: Matrix3::identity(), translation: Vector3::new(x, y, z) }
    }
    /// Pure rotation `angle` about a unit `axis` (T^{Rx}, T^{Ry}, T^{Rz} of Eq. A.2-A.4 for the unit axes).
    pub fn rotation(axis: &Vector3<f64>, angle: f64) -> Self {
        Htm { rotation: rotation_about(axis, angle), translation: Vector3::zeros() }
    }
    /// T_{i,k} = T_{i,j} T_{j,k} (Eq. 3.22).
    pub fn compose(&self, other: &Htm) -> Htm {
        Htm {
            rotation: self.rotation * other.rotation,
            translation: self.translation + self.rotation * other.translation,
        }
    }
    /// The `∘` operator of Eq. 3.21: a point given in frame j expressed in frame i.
    pub fn apply(&self, p: &Vector3<f64>) -> Vector3<f64> {
        self.translation + self.rotation * p
    }
    pub fn inverse(&self) -> Htm {
        let rt = self.rotation.transpose();
        Htm { rotation: rt, translation: -(rt * self.translation) }
    }
}

/// Rotation tensor of angle `angle` about the unit vector `axis` (Rodrigues). For the unit axes it
/// equals the rotation blocks of Eq. A.2-A.4.
pub fn rotation_about(axis: &Vector3<f64>, angle: f64) -> Matrix3<f64> {
    let (s, c) = angle.sin_cos();
    rotation_about_sin_cos(axis, s, c)
}

/// [`rotation_about`] from the sine and cosine of the angle.
fn rotation_about_sin_cos(axis: &Vector3<f64>, s: f64, c: f64) -> Matrix3<f64> {
    let (x, y, z) = (axis.x, axis.y, axis.z);
    // The unit axes of Eq. A.2-A.4 directly.
    match (x == 1.0, y == 1.0, z == 1.0) {
        (true, _, _) => return Matrix3::new(1.0, 0.0, 0.0, 0.0, c, -s, 0.0, s, c),
        (_, true, _) => return Matrix3::new(c, 0.0, s, 0.0, 1.0, 0.0, -s, 0.0, c),
        (_, _, true) => return Matrix3::new(c, -s, 0.0, s, c, 0.0, 0.0, 0.0, 1.0),
        _ => {}
    }
    let v = 1.0 - c;
    Matrix3::new(
        c + x * x * v,
        x * y * v - z * s,
        x * z * v + y * s,
        y * x * v + z * s,
        c + y * y * v,
        y * z * v - x * s,
        z * x * v - y * s,
        z * y * v + x * s,
        c + z * z * v,
    )
}

/// A unit rotation or translation axis: one of the frame axes x, y, z (the elementary
/// transforms of Eq. A.1-A.4, nearly every joint) or a general direction. Knowing the frame axis
/// turns `R e` into a column of R and `R R^{Rx|Ry|Rz}(θ)` into a rotation of two columns.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum Axis {
    /// Frame axis 0 (x), 1 (y) or 2 (z).
    Frame(usize),
    General(Vector3<f64>),
}

impl Axis {
    /// The axis of the unit vector `e`, a frame axis when `e` is exactly one.
    pub fn of(e: &Vector3<f64>) -> Axis {
        match (0..3).find(|&k| e[k] == 1.0) {
            Some(k) => Axis::Frame(k),
            None => Axis::General(*e),
        }
    }
    /// R e: the axis in the frame R maps from.
    pub fn in_frame(&self, r: &Matrix3<f64>) -> Vector3<f64> {
        match self {
            Axis::Frame(k) => r.column(*k).into_owned(),
            Axis::General(e) => r * e,
        }
    }
    /// R ← R R_e(θ), with the sine and cosine of θ.
    #[inline]
    pub fn rotate(&self, r: &mut Matrix3<f64>, (s, c): (f64, f64)) {
        // About axis k the columns i = k + 1 and j = k + 2 (cyclic) turn:
        // c_i' = c c_i + s c_j, c_j' = −s c_i + c c_j (Eq. A.2-A.4).
        fn turn<const I: usize, const J: usize>(r: &mut Matrix3<f64>, s: f64, c: f64) {
            let (a, b) = (r.fixed_columns::<1>(I).into_owned(), r.fixed_columns::<1>(J).into_owned());
            r.fixed_columns_mut::<1>(I).copy_from(&(a * c + b * s));
            r.fixed_columns_mut::<1>(J).copy_from(&(b * c - a * s));
        }
        match self {
            Axis::Frame(0) => turn::<1, 2>(r, s, c),
            Axis::Frame(1) => turn::<2, 0>(r, s, c),
            Axis::Frame(_) => turn::<0, 1>(r, s, c),
            Axis::General(e) => *r *= rotation_about_sin_cos(e, s, c),
        }
    }
}

/// The tilde operator of Eq. 3.29: `tilde(a) b = a × b`.
pub fn tilde(a: &Vector3<f64>) -> Matrix3<f64> {
    Matrix3::new(0.0, -a.z, a.y, a.z, 0.0, -a.x, -a.y, a.x, 0.0)
}

/// Yaw-pitch-roll rotation R_z(Φ) R_y(Θ) R_x(Ψ) of the main body (Eq. 3.52).
pub fn yaw_pitch_roll(yaw: f64, pitch: f64, roll: f64) -> Matrix3<f64> {
    rotation_about(&Vector3::z(), yaw) * rotation_about(&Vector3::y(), pitch) * rotation_about(&Vector3::x(), roll)
}

#[cfg(test)]
mod tests {
    use super::*;
    use approx::assert_relative_eq;

    /// The column shortcuts of a frame axis give R e and R R_e(θ) as the matrix products do.
    #[test]
    fn axis_shortcuts_match_the_products() {
        let r = yaw_pitch_roll(0.4, -0.7, 1.1);
        let t = -0.83_f64;
        let general = Vector3::new(1.0, -2.0, 0.5).normalize();
        for (e, frame) in [(Vector3::x(), true), (Vector3::y(), true), (Vector3::z(), true), (general, false), (-Vector3::z(), false)] {
            let axis = Axis::of(&e);
            assert_eq!(matches!(axis, Axis::Frame(_)), frame, "{e:?}");
            assert_relative_eq!(axis.in_frame(&r), r * e, epsilon = 1e-15);
            let mut turned = r;
            axis.rotate(&mut turned, t.sin_cos());
            assert_relative_eq!(turned, r * rotation_about(&e, t), epsilon = 1e-15);
        }
    }

    #[test]
    fn elementary_rotations_match_appendix_a() {
        let t = 0.3_f64;
        let (s, c) = t.sin_cos();
        let rx = Matrix3::new(1.0, 0.0, 0.0, 0.0, c, -s, 0.0, s, c);
        let ry = Matrix3::new(c, 0.0, s, 0.0, 1.0, 0.0, -s, 0.0, c);
        let rz = Matrix3::new(c, -s, 0.0, s, c, 0.0, 0.0, 0.0, 1.0);
        assert_relative_eq!(rotation_about(&Vector3::x(), t), rx, epsilon = 1e-15);
        assert_relative_eq!(rotation_about(&Vector3::y(), t), ry, epsilon = 1e-15);
        assert_relative_eq!(rotation_about(&Vector3::z(), t), rz, epsilon = 1e-15);
    }

    #[test]
    fn compose_and_inverse_round_trip() {
        let a = Htm::displacement(0.1, -0.2, 0.3).compose(&Htm::rotation(&Vector3::y(), 0.7));
        let b = Htm::rotation(&Vector3::new(0.0, 0.6, 0.8), -1.1).compose(&Htm::displacement(1.0, 2.0, -3.0));
        let p = Vector3::new(0.4, 0.5, -0.6);
        assert_relative_eq!(a.compose(&b).apply(&p), a.apply(&b.apply(&p)), epsilon = 1e-14);
        assert_relative_eq!(a.inverse().apply(&a.apply(&p)), p, epsilon = 1e-14);
        let v = Vector3::new(-1.0, 2.0, 0.5);
        assert_relative_eq!(tilde(&p) * v, p.cross(&v), epsilon = 1e-15);
    }
}
