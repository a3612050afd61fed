//! Compliant foot-ground contact (thesis Section 3.4.2, Eq. 3.72-3.74, Table 3.3).
//!
//! The foot is a sphere of radius r (r = 0: the thesis' point foot), the ground a [`Terrain`];
//! the penetration and the normal come from the closest point of the ground to the foot's centre
//! ([`Terrain::proximity`]; on a plane, the tangent plane below the foot). Every vector is in the
//! global frame.

use nalgebra::{Matrix3, Vector3};
use serde::{Deserialize, Serialize};

#[cfg(test)]
use super::terrain::{FlatGround, Slope};
use super::terrain::{Proximity, Terrain};

/// Parameters of the contact law, Eq. 3.72-3.73.
#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
pub struct GroundContact {
    /// Stiffness K_gnd (N/m^p_K).
    pub k_gnd: f64,
    /// Damping D_gnd (N s/m^(p_D+1)).
    pub d_gnd: f64,
    /// Penetration exponent p_K (1.5: Hertz contact of a sphere on a half space, Eq. 3.74).
    pub p_k: f64,
    /// Penetration-rate exponent p_D.
    pub p_d: f64,
    /// Friction coefficient μ.
    pub mu: f64,
    /// Slip velocity v_glim of the linear zone of the Coulomb friction (m/s).
    pub v_glim: f64,
    /// Radius r of the foot sphere (m); 0: the point foot of Section 3.4.2.
    pub foot_radius: f64,
}

#[cfg(test)]
impl Default for GroundContact {
    /// Table 3.3.
    fn default() -> Self {
        GroundContact { k_gnd: 1e6, d_gnd: 5e4, p_k: 1.5, p_d: 0.5, mu: 0.3, v_glim: 1e-4, foot_radius: 0.0 }
    }
}

/// δ^p for δ > 0: √δ and δ √δ for the exponents 1/2 and 3/2 of Table 3.3 (p_D and the Hertz p_K,
/// Eq. 3.74), within two units in the last place of `powf` at a tenth of its cost (a square
/// root is one instruction; `powf` was 3 % of the 75 s walk's instructions); `powf` for any
/// other exponent.
fn power(delta: f64, p: f64) -> f64 {
    if p == 1.5 {
        delta * delta.sqrt()
    } else if p == 0.5 {
        delta.sqrt()
    } else {
        delta.powf(p)
    }
}

/// The force of the ground on the foot and its exact Jacobians.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct ContactForce {
    /// F = F_n n + F_t (N).
    pub force: Vector3<f64>,
    /// F_n ≥ 0 (N).
    pub normal_force: f64,
    /// δ = n · (p_s - p), positive inside the ground, negative (the clearance) above it (m).
    pub penetration: f64,
    /// dδ/dt = -n · v (m/s).
    pub penetration_rate: f64,
    /// Tangential velocity v_g of the foot relative to the ground (m/s).
    pub slip_velocity: Vector3<f64>,
    /// ∂F/∂p.
    pub df_dp: Matrix3<f64>,
    /// ∂F/∂v.
    pub df_dv: Matrix3<f64>,
    /// Power the contact takes from the robot, -F · v (W): the rate of the ground elastic
    /// energy plus the dissipated power.
    pub absorbed_power: f64,
    /// Power dissipated in the contact (W), ≥ 0: -F · v minus the rate of [`Self::elastic_energy`].
    pub dissipated_power: f64,
    /// Energy stored in the ground spring, K δ^(p_K+1) / (p_K + 1) (J).
    pub elastic_energy: f64,
}

impl GroundContact {
    /// The penetration δ at rest under a normal force `f` (N): K δ^p_K = f (Eq. 3.72 without
    /// its damping term).
    pub fn static_penetration(&self, f: f64) -> f64 {
        (f.max(0.0) / self.k_gnd).powf(1.0 / self.p_k)
    }

    /// Contact force on a foot at `p` moving at `v` (the ground is fixed), Eq. 3.72-3.73.
    ///
    /// The penetration δ and the normal n are those of the closest point of the terrain to the
    /// foot's centre p ([`Terrain::proximity`]); on a plane, δ = n · (p_s - p) + r with
    /// p_s = (x, y, h(x, y)) below the foot. The penetration rate is dδ/dt = ∇δ · v (-n · v on a
    /// face). The Jacobians take ∇δ, its derivative and ∂n/∂p from the terrain: exact on faces
    /// and planes, around edges and vertices and for the blended normal inside the ground.
    ///
    /// For δ > 0, F_n = K δ^p_K + D δ^p_D dδ/dt (Eq. 3.72), clamped at zero: the ground never
    /// pulls the foot (no adhesion when the foot leaves the ground faster than the damping
    /// allows). With p_D < 1, ∂F_n/∂p contains D p_D δ^(p_D-1) dδ/dt, unbounded as δ → 0 while
    /// dδ/dt ≠ 0. The friction is Coulomb with a linear zone (Eq. 3.73) on the tangential slip
    /// velocity v_g = v - (n · v) n.
    pub fn force<T: Terrain + ?Sized>(&self, p: &Vector3<f64>, v: &Vector3<f64>, terrain: &T) -> ContactForce {
        self.force_at(terrain.proximity(p, self.foot_radius), v)
    }

    /// The contact force of [`Self::force`] on a foot moving at `v` whose contact geometry with
    /// the ground (for a foot sphere of radius [`Self::foot_radius`]) is `proximity`.
    pub fn force_at(&self, proximity: Proximity, v: &Vector3<f64>) -> ContactForce {
        let Proximity { penetration: delta, normal: n, penetration_gradient: grad, penetration_hessian: hessian, normal_jacobian: dn_dp } = proximity;
        let delta_rate = grad.dot(v);
        let projector = Matrix3::identity() - n * n.transpose();
        let slip = projector * v;
        let mut out = ContactForce {
            force: Vector3::zeros(),
            normal_force: 0.0,
            penetration: delta,
            penetration_rate: delta_rate,
            slip_velocity: slip,
            df_dp: Matrix3::zeros(),
            df_dv: Matrix3::zeros(),
            absorbed_power: 0.0,
            dissipated_power: 0.0,
            elastic_energy: 0.0,
        };
        if delta <= 0.0 {
            return out;
        }
        let spring = self.k_gnd * power(delta, self.p_k);
        let damping = self.d_gnd * power(delta, self.p_d);
        out.elastic_energy = spring * delta / (self.p_k + 1.0);
        let f_n = spring + damping * delta_rate;
        if f_n > 0.0 {
            // ∂F_n/∂δ and ∂F_n/∂(dδ/dt); ∂δ/∂p = ∂(dδ/dt)/∂v = ∇δᵀ, ∂(dδ/dt)/∂p = vᵀ ∂∇δ/∂p.
            let dfn_ddelta = self.p_k * spring / delta + self.p_d * damping / delta * delta_rate;
            let mut dfn_dp = dfn_ddelta * grad.transpose();
            if hessian != Matrix3::zeros() {
                dfn_dp += damping * (v.transpose() * hessian);
            }
            let dfn_dv = damping * grad.transpose();
            // F_t = F_n t(v_g): ∂F_t/∂F_n = t and ∂F_t/∂v_g.
            let speed = slip.norm();
            let (direction, slip_gain) = if speed < self.v_glim {
                let c = self.mu / self.v_glim;
                (-c * slip, Matrix3::identity() * (-c * f_n))
            } else {
                let u = slip / speed;
                (-self.mu * u, (Matrix3::identity() - u * u.transpose()) * (-self.mu * f_n / speed))
            };
            out.normal_force = f_n;
            out.force = f_n * (n + direction);
            out.df_dp = (n + direction) * dfn_dp;
            out.df_dv = (n + direction) * dfn_dv + slip_gain * projector;
            if dn_dp != Matrix3::zeros() {
                // The turning normal: F_n ∂n/∂p, and ∂v_g/∂p = -(∂n/∂p (n · v) + n vᵀ ∂n/∂p).
                let dslip_dp = -(dn_dp * n.dot(v) + n * (v.transpose() * dn_dp));
                out.df_dp += f_n * dn_dp + slip_gain * dslip_dp;
            }
        }
        out.absorbed_power = -out.force.dot(v);
        out.dissipated_power = out.absorbed_power - spring * delta_rate;
        out
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::test_util::{assert_partial, central, noise, rng};
    use rand::Rng;

    /// The square-root forms of δ^1.5 and δ^0.5 are `powf`'s within two units in the last place,
    /// over the penetrations a foot sees (1e-9 m to 10 cm); other exponents are `powf`'s.
    #[test]
    fn power_is_powf_within_two_ulps() {
        let mut r = rng(73);
        for _ in 0..100_000 {
            let delta = r.random_range((1e-9f64).ln()..(0.1f64).ln()).exp();
            for p in [1.5, 0.5] {
                let (fast, exact) = (power(delta, p), delta.powf(p));
                assert!((fast - exact).abs() <= 2.0 * f64::EPSILON * exact, "{delta}^{p}: {fast} vs {exact}");
            }
            assert_eq!(power(delta, 1.3).to_bits(), delta.powf(1.3).to_bits());
        }
    }

    /// Central differences of F in p and v with steps `hp`, `hv` that cross no kink.
    fn finite_difference_check(contact: &GroundContact, terrain: &dyn Terrain, p: Vector3<f64>, v: Vector3<f64>, hp: f64, hv: f64) {
        let c = contact.force(&p, &v, terrain);
        let scale = c.force.norm();
        for j in 0..3 {
            for i in 0..3 {
                let fp = |x: f64| {
                    let mut q = p;
                    q[j] = x;
                    contact.force(&q, &v, terrain).force[i]
                };
                let fv = |x: f64| {
                    let mut w = v;
                    w[j] = x;
                    contact.force(&p, &w, terrain).force[i]
                };
                let what = format!("∂F_{i}/∂p_{j} at δ = {:e}, v = {v:?}", c.penetration);
                assert_partial(&what, c.df_dp[(i, j)], central(fp, p[j], hp), 1e-5, 1e-8 * c.df_dp.norm() + noise(scale, hp));
                let what = format!("∂F_{i}/∂v_{j} at δ = {:e}, v = {v:?}", c.penetration);
                assert_partial(&what, c.df_dv[(i, j)], central(fv, v[j], hv), 1e-5, 1e-8 * c.df_dv.norm() + noise(scale, hv));
            }
        }
    }

    #[test]
    fn jacobians_match_finite_differences() {
        let contact = GroundContact::default();
        let flat = FlatGround { height: 0.02 };
        let slope = Slope::from_angle(-0.1, 20f64.to_radians(), 0.7);
        let mut r = rng(21);
        for k in 0..400 {
            let terrain: &dyn Terrain = if k % 2 == 0 { &flat } else { &slope };
            let (x, y) = (r.random_range(-1.0..1.0), r.random_range(-1.0..1.0));
            let (h, n) = terrain.height_normal(x, y);
            let delta = (r.random_range((1e-6f64).ln()..(5e-3f64).ln())).exp();
            let p = Vector3::new(x, y, h - delta / n.z);
            // Slip inside or outside the linear zone of Eq. 3.73, penetration rate of either sign
            // (F_n stays above 5 % of K δ^p_K: away from the no-adhesion clamp).
            let t1 = n.cross(&Vector3::x()).normalize();
            let t2 = n.cross(&t1);
            let slip = contact.v_glim * if k % 4 < 2 { r.random_range(0.01..0.99) } else { r.random_range(1.01..100.0) };
            let a = r.random_range(0.0..std::f64::consts::TAU);
            let rate = r.random_range(-0.95..2.0) * contact.k_gnd * delta / contact.d_gnd;
            let v = slip * (a.cos() * t1 + a.sin() * t2) - rate * n;
            let c = contact.force(&p, &v, terrain);
            assert!(c.normal_force > 0.05 * contact.k_gnd * delta.powf(1.5));
            assert!((c.slip_velocity.norm() - slip).abs() < 1e-9 * slip);
            finite_difference_check(&contact, terrain, p, v, 1e-4 * delta, 1e-4 * slip.min((slip - contact.v_glim).abs()));
        }
    }

    #[test]
    fn jacobians_match_finite_differences_inside_the_ground_near_edges() {
        // Point feet sunk 0.2-2 mm into a step's top corner and into a rough heightfield, within
        // a millimetre of an edge: the blended normal's derivative (terrain module docs) enters
        // ∂F/∂p through F_n n and the slip's projector; and foot spheres around the edges.
        use crate::physics::terrain::{Heightfield, Step};
        let contact = GroundContact::default();
        let step = Step { base: 0.0, rise: 0.08, edge: 1.0, azimuth: 0.3 };
        let mut r = rng(22);
        let heights = (0..8).map(|_| (0..8).map(|_| r.random_range(-0.05..0.05)).collect()).collect();
        let field = Heightfield::new([0.0, 0.0], 0.1, heights).unwrap();
        let mut blended = 0;
        for k in 0..300 {
            // One in ten, under the step's top, in the blend's fade with the depth (5-7 cm).
            let delta = if k % 10 == 8 { r.random_range(0.05..0.07) } else { (r.random_range((2e-4f64).ln()..(2e-3f64).ln())).exp() };
            let (terrain, p): (&dyn Terrain, Vector3<f64>) = if k % 2 == 0 {
                // Across the corner: s = δ (-1.5..1.5) from the face, δ under the top.
                let u = Vector3::new(step.azimuth.cos(), step.azimuth.sin(), 0.0);
                let along = Vector3::new(-u.y, u.x, 0.0) * r.random_range(-1.0..1.0);
                (&step, u * (step.edge + delta * r.random_range(-1.5..1.5)) + along + Vector3::new(0.0, 0.0, step.rise - delta))
            } else {
                // Near the cell edge x = 0.3 (or the diagonal through (0.3, 0.3)).
                let (x, y) = (0.3 + delta * r.random_range(-1.5..1.5), r.random_range(0.25..0.35));
                (&field, Vector3::new(x, y, field.height_normal(x, y).0 - delta))
            };
            // Every third a foot sphere of 5 mm, its centre above the ground near the edge (the
            // direction to the edge turns as it moves).
            let (contact, p) = if k % 3 == 2 { (GroundContact { foot_radius: 5e-3, ..contact }, p + Vector3::new(0.0, 0.0, 5e-3)) } else { (contact, p) };
            let proximity = terrain.proximity(&p, contact.foot_radius);
            blended += usize::from(proximity.normal_jacobian != Matrix3::zeros());
            let n = proximity.normal;
            let t1 = n.cross(&Vector3::x()).normalize();
            let t2 = n.cross(&t1);
            let slip = contact.v_glim * if k % 4 < 2 { r.random_range(0.01..0.99) } else { r.random_range(1.01..100.0) };
            let a = r.random_range(0.0..std::f64::consts::TAU);
            let v = slip * (a.cos() * t1 + a.sin() * t2) - r.random_range(-0.5..0.5) * contact.k_gnd * delta / contact.d_gnd * n;
            if proximity.penetration > 0.0 {
                finite_difference_check(&contact, terrain, p, v, 1e-5 * delta, 1e-4 * slip.min((slip - contact.v_glim).abs()));
            }
        }
        assert!(blended > 100, "only {blended} of 300 points in a blend");
    }

    #[test]
    fn static_normal_force_follows_hertz() {
        let contact = GroundContact::default();
        let ground = FlatGround { height: 0.0 };
        for delta in [1e-5, 1e-4, 2.3e-3] {
            let c = contact.force(&Vector3::new(0.3, -0.2, -delta), &Vector3::zeros(), &ground);
            let hertz = contact.k_gnd * f64::powf(delta, 1.5);
            assert!((c.normal_force - hertz).abs() < 1e-12 * hertz);
            assert!((c.force - Vector3::new(0.0, 0.0, hertz)).norm() < 1e-12 * hertz);
            assert!((c.penetration - delta).abs() < 1e-15);
        }
        // Table 3.3 calibration: about 2.3 mm under a third of the 34 kg robot (Section 3.4.2).
        let delta = (34.0 * 9.81 / 3.0 / contact.k_gnd).powf(1.0 / 1.5);
        assert!((delta - 2.3e-3).abs() < 0.1e-3, "{delta}");
    }

    #[test]
    fn friction_saturates_at_mu_normal_force() {
        let contact = GroundContact::default();
        let ground = FlatGround { height: 0.0 };
        let p = Vector3::new(0.0, 0.0, -1e-3);
        for speed in [1e-3, 1e-2, 1.0] {
            let c = contact.force(&p, &Vector3::new(0.6 * speed, -0.8 * speed, 0.0), &ground);
            let ft = c.force - c.normal_force * Vector3::z();
            assert!((ft.norm() - contact.mu * c.normal_force).abs() < 1e-12 * c.normal_force);
            assert!(ft.dot(&c.slip_velocity) < 0.0);
        }
        let c = contact.force(&p, &Vector3::new(0.5 * contact.v_glim, 0.0, 0.0), &ground);
        assert!((c.force.x + 0.5 * contact.mu * c.normal_force).abs() < 1e-12 * c.normal_force);
    }

    #[test]
    fn no_force_above_ground_and_no_adhesion() {
        let contact = GroundContact::default();
        let slope = Slope::from_angle(0.0, 0.3, 1.0);
        let (h, _) = slope.height_normal(0.2, 0.1);
        let above = contact.force(&Vector3::new(0.2, 0.1, h + 1e-4), &Vector3::new(0.1, 0.0, -0.1), &slope);
        assert_eq!(above.force, Vector3::zeros());
        assert_eq!(above.df_dp, Matrix3::zeros());
        assert!(above.penetration < 0.0);
        // Leaving the ground fast: the damping would pull, the force is clamped at zero.
        let ground = FlatGround { height: 0.0 };
        let leaving = contact.force(&Vector3::new(0.0, 0.0, -1e-4), &Vector3::new(0.0, 0.0, 1.0), &ground);
        assert_eq!(leaving.normal_force, 0.0);
        assert_eq!(leaving.force, Vector3::zeros());
        assert!(leaving.dissipated_power > 0.0);
    }

    #[test]
    fn dissipated_power_is_non_negative() {
        let contact = GroundContact::default();
        let ground = FlatGround { height: 0.0 };
        let mut r = rng(22);
        for _ in 0..1000 {
            let p = Vector3::new(0.0, 0.0, -r.random_range(0.0..5e-3));
            let v = Vector3::new(r.random_range(-1e-3..1e-3), r.random_range(-1e-3..1e-3), r.random_range(-0.1..0.1));
            let c = contact.force(&p, &v, &ground);
            assert!(c.dissipated_power >= -1e-12 * (1.0 + c.absorbed_power.abs()), "{c:?}");
            let elastic_rate = contact.k_gnd * c.penetration.max(0.0).powf(1.5) * c.penetration_rate;
            assert!((c.absorbed_power - c.dissipated_power - elastic_rate).abs() < 1e-9 * (1.0 + c.absorbed_power.abs()));
        }
    }
}
