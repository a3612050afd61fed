//! The desired body motion integrated from the global velocities (thesis Section 7.4,
//! Eq. 7.12-7.23): positions by the trapezoidal rule, yaw-pitch-roll angles by a
//! predictor-corrector on their rates through the velocity transformation matrix J_ω.

use nalgebra::{Matrix3, Vector3};

use crate::spatial::{rotation_about, Htm};

/// Body pose (X, Y, Z, Φ, Θ, Ψ) as in Eq. 3.52 and 7.12.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct Pose {
    pub position: Vector3<f64>,
    /// Yaw Φ, pitch Θ, roll Ψ.
    pub angles: Vector3<f64>,
}

impl Pose {
    /// T_{0,b} = T^d(X, Y, Z) T^Rz(Φ) T^Ry(Θ) T^Rx(Ψ) (Eq. 7.12).
    pub fn htm(&self) -> Htm {
        Htm { rotation: crate::spatial::yaw_pitch_roll(self.angles.x, self.angles.y, self.angles.z), translation: self.position }
    }
}

/// J_ω of Eq. 7.16: ω = J_ω (Φ', Θ', Ψ')ᵀ for the yaw-pitch-roll sequence.
pub fn angular_velocity_matrix(angles: &Vector3<f64>) -> Matrix3<f64> {
    let (yaw, pitch) = (angles.x, angles.y);
    let ez = Vector3::z();
    let ey = rotation_about(&ez, yaw) * Vector3::y();
    let ex = rotation_about(&ez, yaw) * rotation_about(&Vector3::y(), pitch) * Vector3::x();
    Matrix3::from_columns(&[ez, ey, ex])
}

/// The desired body HTM T*_{0,b}, advanced every control step from the global velocities
/// v_{b/0} and ω_{b/0} (Eq. 7.4-7.5).
#[derive(Clone, Debug, PartialEq)]
pub struct BodyMotion {
    pub pose: Pose,
    velocity: Vector3<f64>,
    omega: Vector3<f64>,
    /// Yaw-pitch-roll rates at the last step.
    rates: Vector3<f64>,
}

impl BodyMotion {
    pub fn new(pose: Pose) -> Self {
        BodyMotion { pose, velocity: Vector3::zeros(), omega: Vector3::zeros(), rates: Vector3::zeros() }
    }

    /// Advances by Δt to the new velocities (v^{k+1}, ω^{k+1}).
    pub fn step(&mut self, velocity: Vector3<f64>, omega: Vector3<f64>, dt: f64) -> Pose {
        // Eq. 7.13-7.15.
        self.pose.position += (self.velocity + velocity) * (0.5 * dt);
        // Eq. 7.17-7.19: prediction with the previous rates.
        let predicted = self.pose.angles + self.rates * dt;
        // Eq. 7.20: rates at k+1 from J_ω at the predicted angles. The matrix is singular at
        // pitch = ±90°, far outside a walking robot's attitudes.
        let rates = angular_velocity_matrix(&predicted).try_inverse().expect("pitch away from ±90°") * omega;
        // Eq. 7.21-7.23: correction.
        self.pose.angles += (self.rates + rates) * (0.5 * dt);
        self.rates = rates;
        self.velocity = velocity;
        self.omega = omega;
        self.pose
    }

    pub fn velocity(&self) -> Vector3<f64> {
        self.velocity
    }
    pub fn omega(&self) -> Vector3<f64> {
        self.omega
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use approx::assert_relative_eq;

    /// J_ω against the numerical derivative of the rotation (Eq. 3.28-3.30).
    #[test]
    fn angular_velocity_matrix_matches_the_rotation_derivative() {
        let a = Vector3::new(0.4, -0.3, 0.2);
        let rates = Vector3::new(0.1, -0.2, 0.3);
        let dt = 1e-6;
        let r = |a: Vector3<f64>| crate::spatial::yaw_pitch_roll(a.x, a.y, a.z);
        let rdot = (r(a + rates * dt) - r(a - rates * dt)) / (2.0 * dt);
        let w = rdot * r(a).transpose();
        let omega = Vector3::new(w[(2, 1)], w[(0, 2)], w[(1, 0)]);
        assert_relative_eq!(angular_velocity_matrix(&a) * rates, omega, epsilon = 1e-9);
    }

    /// A constant yaw rate and forward velocity in the body frame draw a circle: after a full
    /// turn the body is back where it started. (The first step ramps the rates up from rest, so
    /// the integrated time is N Δt − Δt/2.)
    #[test]
    fn turning_on_a_circle_closes() {
        let mut m = BodyMotion::new(Pose::default());
        let (radius, omega_z, dt) = (0.5, 0.05, 0.01);
        let steps = (2.0 * std::f64::consts::PI / omega_z / dt + 0.5).round() as usize;
        for _ in 0..steps {
            let yaw = m.pose.angles.x;
            let v = Vector3::new(yaw.cos(), yaw.sin(), 0.0) * radius * omega_z;
            m.step(v, Vector3::new(0.0, 0.0, omega_z), dt);
        }
        let turned = omega_z * dt * (steps as f64 - 0.5);
        assert_relative_eq!(m.pose.angles.x, turned, epsilon = 1e-12);
        assert!((turned - 2.0 * std::f64::consts::PI).abs() < omega_z * dt);
        assert!(m.pose.position.norm() < 1e-4, "{:?}", m.pose.position);
    }

    /// Rotations about tilted axes integrate consistently: the HTM rotation matches the
    /// exponential of the constant global ω.
    #[test]
    fn constant_global_rotation_matches_the_exponential() {
        let mut m = BodyMotion::new(Pose::default());
        let omega = Vector3::new(0.02, -0.03, 0.05);
        for _ in 0..1000 {
            m.step(Vector3::zeros(), omega, 0.01);
        }
        let exact = rotation_about(&omega.normalize(), omega.norm() * (10.0 - 0.005));
        assert_relative_eq!(m.pose.htm().rotation, exact, epsilon = 1e-6);
    }
}
