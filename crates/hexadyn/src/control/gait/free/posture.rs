//! Posture control, Rule 1 of the free gait (thesis Section 7.7.1, Fig. 7.25, Eq. 7.32-7.37):
//! when a new leg touches the ground, the body displacement (Δz, Δψ, Δθ) that brings the feet
//! closest to their well-conditioned heights is found by the simplex method of Nelder and Mead
//! (the thesis used the GSL's; here argmin's) and spread over t_post as body velocities.

use argmin::core::{CostFunction, Error, Executor, State};
use argmin::solver::neldermead::NelderMead;
use nalgebra::{Matrix3, Vector3};

use crate::spatial::yaw_pitch_roll;

/// The posture displacement of Eq. 7.34 (body frame): height Δz, roll Δψ, pitch Δθ.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct PostureCorrection {
    pub dz: f64,
    pub droll: f64,
    pub dpitch: f64,
}

impl PostureCorrection {
    /// T_posture = T^d(0, 0, Δz) T^Ry(Δθ) T^Rx(Δψ) (Eq. 7.34) applied inversely to a foot
    /// position p⁰_F/b: {p_F/b}_b = T_posture⁻¹ ∘ p⁰_F/b (Eq. 7.33).
    pub fn foot_after(&self, p0: &Vector3<f64>) -> Vector3<f64> {
        let r = yaw_pitch_roll(0.0, self.dpitch, self.droll);
        r.transpose() * (p0 - Vector3::new(0.0, 0.0, self.dz))
    }

    /// Body-frame velocities over t_post (Eq. 7.35-7.37): (v_z, ω_x, ω_y).
    pub fn velocities(&self, t_post: f64) -> (f64, f64, f64) {
        (self.dz / t_post, self.droll / t_post, self.dpitch / t_post)
    }
}

/// The criterion D of Eq. 7.32 for the feet `p0` (body frame; for a leg in the air its last
/// contact point) and their reference heights p_z,C/b.
struct Criterion<'a> {
    p0: &'a [Vector3<f64>],
    reference: &'a [f64],
}

impl Criterion<'_> {
    /// Eq. 7.32.
    fn d(&self, c: &PostureCorrection) -> f64 {
        self.p0.iter().zip(self.reference).map(|(p, z)| (c.foot_after(p).z - z).powi(2)).sum()
    }
}

impl CostFunction for Criterion<'_> {
    type Param = Vec<f64>;
    type Output = f64;
    fn cost(&self, p: &Vec<f64>) -> Result<f64, Error> {
        Ok(self.d(&PostureCorrection { dz: p[0], droll: p[1], dpitch: p[2] }))
    }
}

/// Initial simplex edges: 1 cm in height, 0.05 rad in roll and pitch.
const SIMPLEX_STEP: [f64; 3] = [0.01, 0.05, 0.05];
/// The simplex stops when the standard deviation of its criterion values is below this (m²):
/// the feet heights are then settled to about 1e-7 m.
const SD_TOLERANCE: f64 = 1e-14;
const MAX_ITERATIONS: u64 = 1000;

/// Minimizes Eq. 7.32 over (Δz, Δψ, Δθ) by Nelder-Mead from no displacement. `p0` and
/// `reference` have one entry per leg taking part (the six, or five with a failed leg). The
/// error is the solver's (it does not fail for finite inputs).
pub fn solve_posture(p0: &[Vector3<f64>], reference: &[f64]) -> Result<PostureCorrection, Error> {
    let criterion = Criterion { p0, reference };
    let start = vec![0.0; 3];
    let simplex = std::iter::once(start.clone())
        .chain((0..3).map(|i| {
            let mut v = start.clone();
            v[i] = SIMPLEX_STEP[i];
            v
        }))
        .collect();
    let solver = NelderMead::new(simplex).with_sd_tolerance(SD_TOLERANCE)?;
    let result = Executor::new(criterion, solver).configure(|s| s.max_iters(MAX_ITERATIONS)).timer(false).run()?;
    let best = result.state().get_best_param().ok_or_else(|| Error::msg("no best parameter"))?;
    Ok(PostureCorrection { dz: best[0], droll: best[1], dpitch: best[2] })
}

/// Height of the body origin above the least-squares plane z = a + b x + c y through the contact
/// points (body frame): the body clearance with respect to the estimated ground plane of
/// Section 7.7.5, and the plane's unit normal (body frame, upwards). `None` for fewer than three
/// points or collinear ones.
pub fn ground_plane(points: &[Vector3<f64>]) -> Option<(f64, Vector3<f64>)> {
    let mut a = Matrix3::zeros();
    let mut rhs = Vector3::zeros();
    for p in points {
        let row = Vector3::new(1.0, p.x, p.y);
        a += row * row.transpose();
        rhs += row * p.z;
    }
    let coefficients = a.try_inverse()? * rhs;
    let normal = Vector3::new(-coefficients.y, -coefficients.z, 1.0);
    let norm = normal.norm();
    (points.len() >= 3 && norm.is_finite()).then(|| (-coefficients.x / norm, normal / norm))
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::test_util::rng;
    use rand::Rng;

    /// Fig. 7.25: feet on a plane tilted by known angles at a known distance below the body; the
    /// displacement that puts them back at a uniform reference height is the plane's own pitch
    /// and roll, and the height difference. Independent oracle: the least-squares plane, whose
    /// minimum of Eq. 7.32 is exactly zero here.
    #[test]
    fn posture_recovers_a_tilted_ground_plane() {
        let mut r = rng(77);
        for _ in 0..200 {
            let (pitch, roll) = (r.random_range(-0.35..0.35), r.random_range(-0.2..0.2));
            let h = r.random_range(0.12..0.2);
            let href = 0.16;
            // The ground in the body frame: the plane of the feet of a body rotated by (pitch,
            // roll) about its origin, h above it.
            let rot = yaw_pitch_roll(0.0, pitch, roll);
            let feet: Vec<Vector3<f64>> = (0..6)
                .map(|l| {
                    let a = (30.0 + 60.0 * l as f64).to_radians();
                    let xy = Vector3::new(0.45 * a.cos(), 0.45 * a.sin(), -h) + Vector3::new(r.random_range(-0.05..0.05), r.random_range(-0.05..0.05), 0.0);
                    rot * xy
                })
                .collect();
            let reference = vec![-href; 6];
            let c = solve_posture(&feet, &reference).unwrap();
            let residual = Criterion { p0: &feet, reference: &reference }.d(&c);
            assert!(residual < 1e-10, "{c:?}: D = {residual}");
            let (height, _) = ground_plane(&feet.iter().map(|p| c.foot_after(p)).collect::<Vec<_>>()).unwrap();
            assert!((height - href).abs() < 1e-5, "{height}");
            assert!((c.dpitch - pitch).abs() < 1e-4 && (c.droll - roll).abs() < 1e-4, "{c:?} vs pitch {pitch}, roll {roll}");
        }
    }

    #[test]
    fn ground_plane_of_a_known_plane() {
        let plane = |x: f64, y: f64| -0.15 + 0.2 * x - 0.1 * y;
        let pts: Vec<Vector3<f64>> = [(0.3, 0.2), (-0.3, 0.25), (0.0, -0.3), (0.1, 0.0)].iter().map(|&(x, y)| Vector3::new(x, y, plane(x, y))).collect();
        let (h, n) = ground_plane(&pts).unwrap();
        let expected_n = Vector3::new(-0.2, 0.1, 1.0).normalize();
        assert!((n - expected_n).norm() < 1e-12);
        assert!((h - 0.15 * expected_n.z).abs() < 1e-12);
        assert!(ground_plane(&pts[..2]).is_none());
    }
}
