//! Correction of the global velocities (thesis Section 7.7.2, Fig. 7.26, Eq. 7.38-7.48): the
//! posture velocities, normal to the body plane, are merged with the heading velocities so that
//! the horizontal velocity (V_x, V_y) and the yaw rate Ω_z the user commands are kept.

use nalgebra::Vector3;

/// The global body velocities v_b and ω_b given to the support phase algorithm.
///
/// `v_traj`, `omega_traj`: the heading velocities (V_x, V_y, 0) and (0, 0, Ω_z) (global);
/// `v_post` = v_z n and `omega_post` = ω_x x_b + ω_y y_b: the posture velocities of Eq.
/// 7.35-7.37 expressed in the global frame; `n`: the unit normal of the body plane (z_b in the
/// global frame, n · u_z > 0 for any attitude a walking robot has).
pub fn corrected_velocities(v_traj: &Vector3<f64>, omega_traj: &Vector3<f64>, v_post: &Vector3<f64>, omega_post: &Vector3<f64>, n: &Vector3<f64>) -> (Vector3<f64>, Vector3<f64>) {
    let u_z = Vector3::z();
    let n_z = n.dot(&u_z);
    // Eq. 7.43: v_post + v_corr = V u_z with V = (v_post · n)/(u_z · n) (Eq. 7.39-7.42).
    let v_b = v_traj + u_z * (v_post.dot(n) / n_z);
    // Eq. 7.48: ω_corr = −(ω_post · u_z)/(n · u_z) n keeps the Z component (Eq. 7.44-7.47).
    let omega_b = omega_traj + omega_post - n * (omega_post.dot(&u_z) / n_z);
    (v_b, omega_b)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::spatial::yaw_pitch_roll;
    use proptest::prelude::*;

    proptest! {
        #![proptest_config(ProptestConfig::with_cases(10_000))]
        /// Section 7.7.2: whatever the attitude and the posture velocities, the corrected
        /// velocities keep the commanded X, Y velocities and yaw rate (to 1e-12), move the body
        /// along its normal as the posture asks (v_b − v_traj) · n = v_post · n, and turn it
        /// about the axes of its plane as the posture asks (ω_b − ω_traj − ω_post parallel to n).
        #[test]
        fn velocity_correction_keeps_the_heading(
            vx in -0.05f64..0.05, vy in -0.05f64..0.05, wz in -0.05f64..0.05,
            yaw in -3.2f64..3.2, pitch in -0.6f64..0.6, roll in -0.6f64..0.6,
            vz in -0.05f64..0.05, wx in -0.2f64..0.2, wy in -0.2f64..0.2,
        ) {
            let r = yaw_pitch_roll(yaw, pitch, roll);
            let n = r * Vector3::z();
            let v_traj = Vector3::new(vx, vy, 0.0);
            let omega_traj = Vector3::new(0.0, 0.0, wz);
            let v_post = n * vz;
            let omega_post = r * Vector3::new(wx, wy, 0.0);
            let (v_b, omega_b) = corrected_velocities(&v_traj, &omega_traj, &v_post, &omega_post, &n);
            prop_assert!((v_b.x - vx).abs() <= 1e-12 && (v_b.y - vy).abs() <= 1e-12, "{v_b:?}");
            prop_assert!((omega_b.z - wz).abs() <= 1e-12, "{omega_b:?}");
            prop_assert!(((v_b - v_traj).dot(&n) - v_post.dot(&n)).abs() <= 1e-12);
            prop_assert!((omega_b - omega_traj - omega_post).cross(&n).norm() <= 1e-12);
        }
    }

    /// The simple sum the correction replaces does not keep the heading on a tilted body: the
    /// property above is not true of any sum.
    #[test]
    fn the_plain_sum_drifts_on_a_slope() {
        let r = yaw_pitch_roll(0.0, 20f64.to_radians(), 0.0);
        let n = r * Vector3::z();
        let v_post = n * 0.01;
        assert!((Vector3::new(0.01, 0.0, 0.0) + v_post).x - 0.01 > 1e-3);
        let (v_b, _) = corrected_velocities(&Vector3::new(0.01, 0.0, 0.0), &Vector3::zeros(), &v_post, &Vector3::zeros(), &n);
        assert_eq!(v_b.x, 0.01);
    }
}
