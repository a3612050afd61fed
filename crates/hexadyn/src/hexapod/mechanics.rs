//! The multibody model of the hexapod (thesis Section 3.4.1, Eq. 3.51-3.71): 1 free main body
//! and, per leg, a chassis on q_r, the four pantograph links through the dependent parameters
//! p0 and p1, and three rotors turning at n q. For AMRU5: 49 bodies, 24 DOF.

use std::f64::consts::PI;
use std::sync::Arc;

use nalgebra::{Matrix3, Vector3};

use super::pantograph::PantographGeometry;
use super::{joint_index, DOF};
use crate::spatial::Htm;
use crate::mbs::{BodyId, BodySpec, Elementary, Model, ModelBuilder, ModelError, Var};

/// Mass and central inertia (principal moments in the body frame), Table B.2.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Inertia {
    pub mass: f64,
    pub moments: Vector3<f64>,
}

impl Inertia {
    fn tensor(&self) -> Matrix3<f64> {
        Matrix3::from_diagonal(&self.moments)
    }
}

/// Everything the mechanics needs (SI units), gathered from the robot description.
#[derive(Clone, Debug, PartialEq)]
pub struct MechanicsParameters {
    pub pantograph: PantographGeometry,
    /// Angle α of each leg's q_r axis about z_b, from x_b (NOTES.md: 30°, −30°, 90°, −90°, 150°, −150°).
    pub leg_angles: [f64; 6],
    /// R_rot: body centre to the q_r axis.
    pub r_rot: f64,
    /// O_l → G_c (L_x1, L_y1, L_z1).
    pub chassis_cog: Vector3<f64>,
    /// G_c → C* (L_xc, L_yc, L_zc).
    pub crossing_point: Vector3<f64>,
    /// Centre of gravity of each pantograph link along its axis: A→G0, B→G1, D→G2, C→G3.
    pub link_cog: [f64; 4],
    /// Rotor of q_r: main-body centre to rotor along the leg direction (L_x6).
    pub rotor_r_radius: f64,
    /// C* → rotor of q_v (L_x7, L_y7, L_z7) and of q_h (L_x8, L_y8, L_z8).
    pub rotor_v: Vector3<f64>,
    pub rotor_h: Vector3<f64>,
    /// Global reductions n_r, n_v, n_h (Table 3.1).
    pub reductions: [f64; 3],
    pub body: Inertia,
    pub chassis: Inertia,
    pub links: [Inertia; 4],
    pub rotor_mass: f64,
    /// Axial and equatorial rotor inertia (I_a, I_e).
    pub rotor_axial: f64,
    pub rotor_equatorial: f64,
}

/// Body and coordinate indices of one leg.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct LegBodies {
    pub chassis: BodyId,
    pub links: [BodyId; 4],
    pub rotors: [BodyId; 3],
    /// Index of q_r in q; q_v and q_h follow.
    pub first_coordinate: usize,
}

/// The compiled hexapod mechanics.
#[derive(Clone, Debug)]
pub struct Mechanics {
    pub model: Model,
    pub body: BodyId,
    pub legs: [LegBodies; 6],
    /// Foot F in the frame of link 3 (the leg).
    pub foot_local: Vector3<f64>,
    pub parameters: MechanicsParameters,
}

impl Mechanics {
    pub fn new(p: &MechanicsParameters) -> Result<Self, ModelError> {
        let mut b = ModelBuilder::new(DOF);
        // Main body, Eq. 3.52: T_{0,b} = T^d(X, Y, Z) T^Rz(Φ) T^Ry(Θ) T^Rx(Ψ).
        let body = b.add_body(BodySpec {
            name: "body".into(),
            parent: None,
            joint: Elementary::free_body(0),
            mass: p.body.mass,
            inertia: p.body.tensor(),
        })?;
        let pg = &p.pantograph;
        let [ag0, bg1, dg2, cg3] = p.link_cog;
        let c_star = p.crossing_point;
        let rotor = |axis: usize| {
            let mut m = Vector3::repeat(p.rotor_equatorial);
            m[axis] = p.rotor_axial;
            Matrix3::from_diagonal(&m)
        };
        let mut legs = Vec::with_capacity(6);
        for (leg, &alpha) in p.leg_angles.iter().enumerate() {
            let j = joint_index(leg, 0);
            let pantograph = b.add_dependent(&[j + 1, j + 2], Arc::new(*pg))?;
            let (p0, p1) = (Var::p(pantograph), Var::p(pantograph + 1));
            let name = |part: &str| format!("leg{leg}.{part}");
            // Eq. 3.64: T_{0,c} = T_{0,b} T^Rz(α) T^d(O_b O_l) T^Rz(−q_r) T^d(O_l G_c).
            let chassis = b.add_body(BodySpec {
                name: name("chassis"),
                parent: Some(body),
                joint: vec![
                    Elementary::Fixed(Htm::rotation(&Vector3::z(), alpha)),
                    Elementary::offset(p.r_rot, 0.0, 0.0),
                    Elementary::rz(Var::q(j).scaled(-1.0)),
                    Elementary::offset(p.chassis_cog.x, p.chassis_cog.y, p.chassis_cog.z),
                ],
                mass: p.chassis.mass,
                inertia: p.chassis.tensor(),
            })?;
            // Eq. 3.65: link 0 from A = C* + (0, 0, q_v), rotated by −p0.
            let link0 = b.add_body(BodySpec {
                name: name("link0"),
                parent: Some(chassis),
                joint: vec![Elementary::offset(c_star.x, c_star.y, c_star.z), Elementary::tz(Var::q(j + 1)), Elementary::ry(p0.scaled(-1.0)), Elementary::offset(ag0, 0.0, 0.0)],
                mass: p.links[0].mass,
                inertia: p.links[0].tensor(),
            })?;
            // Eq. 3.66: link 1 from B, at π − p1 from link 0.
            let link1 = b.add_body(BodySpec {
                name: name("link1"),
                parent: Some(link0),
                joint: vec![Elementary::offset(pg.c - ag0, 0.0, 0.0), Elementary::ry(p1.scaled(-1.0).plus(PI)), Elementary::offset(bg1, 0.0, 0.0)],
                mass: p.links[1].mass,
                inertia: p.links[1].tensor(),
            })?;
            // Eq. 3.67: link 2 from D = C* + (q_h, 0, 0), parallel to link 0.
            let link2 = b.add_body(BodySpec {
                name: name("link2"),
                parent: Some(chassis),
                joint: vec![Elementary::offset(c_star.x, c_star.y, c_star.z), Elementary::tx(Var::q(j + 2)), Elementary::ry(p0.scaled(-1.0)), Elementary::offset(dg2, 0.0, 0.0)],
                mass: p.links[2].mass,
                inertia: p.links[2].tensor(),
            })?;
            // Eq. 3.68: link 3 (the leg) from C, parallel to link 1.
            let link3 = b.add_body(BodySpec {
                name: name("link3"),
                parent: Some(link0),
                joint: vec![Elementary::offset(pg.l0 - ag0, 0.0, 0.0), Elementary::ry(p1.scaled(-1.0).plus(PI)), Elementary::offset(cg3, 0.0, 0.0)],
                mass: p.links[3].mass,
                inertia: p.links[3].tensor(),
            })?;
            // Eq. 3.69-3.71: rotors turning at n q relative to the chassis.
            let [n_r, n_v, n_h] = p.reductions;
            let rr = p.rotor_r_radius - p.r_rot;
            let rotor_r = b.add_body(BodySpec {
                name: name("rotor_r"),
                parent: Some(chassis),
                joint: vec![Elementary::offset(rr - p.chassis_cog.x, -p.chassis_cog.y, -p.chassis_cog.z), Elementary::rz(Var::q(j).scaled(n_r))],
                mass: p.rotor_mass,
                inertia: rotor(2),
            })?;
            let v = c_star + p.rotor_v;
            let rotor_v = b.add_body(BodySpec { name: name("rotor_v"), parent: Some(chassis), joint: vec![Elementary::offset(v.x, v.y, v.z), Elementary::rz(Var::q(j + 1).scaled(n_v))], mass: p.rotor_mass, inertia: rotor(2) })?;
            let h = c_star + p.rotor_h;
            let rotor_h = b.add_body(BodySpec { name: name("rotor_h"), parent: Some(chassis), joint: vec![Elementary::offset(h.x, h.y, h.z), Elementary::rx(Var::q(j + 2).scaled(n_h))], mass: p.rotor_mass, inertia: rotor(0) })?;
            legs.push(LegBodies { chassis, links: [link0, link1, link2, link3], rotors: [rotor_r, rotor_v, rotor_h], first_coordinate: j });
        }
        Ok(Mechanics {
            model: b.build(),
            body,
            legs: legs.try_into().expect("six legs"),
            foot_local: Vector3::new(pg.l3 - cg3, 0.0, 0.0),
            parameters: p.clone(),
        })
    }
}


#[cfg(test)]
mod tests {
    use super::*;
    use crate::mbs::{kinematics, mass_matrix, Data};
    use crate::description::RobotDescription;
    use crate::spatial::{rotation_about, Htm};
    use approx::assert_relative_eq;
    use nalgebra::DMatrix;

    fn amru5() -> Mechanics {
        Mechanics::new(&MechanicsParameters::from_description(&RobotDescription::amru5())).unwrap()
    }

    /// 49 bodies, 24 DOF (Section 3.4) and the total mass of Table B.2.
    #[test]
    fn counts_and_mass() {
        let m = amru5();
        assert_eq!(m.model.body_count(), 49);
        assert_eq!(m.model.coordinate_count(), 24);
        assert_relative_eq!(m.model.total_mass(), 34.447, epsilon = 1e-9);
    }

    /// The foot of the multibody model sits where the planar linkage puts it, in the leg plane
    /// through C*, for any body pose and q_r.
    #[test]
    fn foot_matches_the_planar_linkage() {
        let mech = amru5();
        let p = &mech.parameters;
        let mut data = Data::new(&mech.model);
        let mut q = vec![0.0; DOF];
        q[..6].copy_from_slice(&[0.1, -0.2, 0.45, 0.3, 0.05, -0.04]);
        for leg in 0..6 {
            q[joint_index(leg, 0)] = 0.1 * leg as f64 - 0.25;
            q[joint_index(leg, 1)] = 0.045 + 0.005 * leg as f64;
            q[joint_index(leg, 2)] = 0.01 + 0.008 * leg as f64;
        }
        kinematics(&mech.model, &mut data, &q, &[0.0; DOF]);
        let body = Htm { rotation: crate::spatial::yaw_pitch_roll(q[3], q[4], q[5]), translation: Vector3::new(q[0], q[1], q[2]) };
        for (leg, bodies) in mech.legs.iter().enumerate() {
            let (qr, qv, qh) = (q[joint_index(leg, 0)], q[joint_index(leg, 1)], q[joint_index(leg, 2)]);
            let f = p.pantograph.foot(qv, qh);
            let c_star = p.chassis_cog + p.crossing_point;
            let in_leg = rotation_about(&Vector3::z(), -qr) * (c_star + Vector3::new(f.x, 0.0, f.y));
            let expected = body.apply(&(rotation_about(&Vector3::z(), p.leg_angles[leg]) * (Vector3::new(p.r_rot, 0.0, 0.0) + in_leg)));
            assert_relative_eq!(data.point(bodies.links[3], &mech.foot_local), expected, epsilon = 1e-12);
        }
    }

    /// The rotors dominate the joint inertia: M_vv ≈ n_v² I_a (Section 4.4.1, τ_m ≈ 5.8 ms).
    #[test]
    fn reflected_rotor_inertia_dominates_the_joint_mass() {
        let mech = amru5();
        let mut data = Data::new(&mech.model);
        let mut q = vec![0.0; DOF];
        for leg in 0..6 {
            q[joint_index(leg, 1)] = 0.06;
            q[joint_index(leg, 2)] = 0.04;
        }
        kinematics(&mech.model, &mut data, &q, &[0.0; DOF]);
        let mut m = DMatrix::zeros(DOF, DOF);
        mass_matrix(&mech.model, &data, &mut m);
        let p = &mech.parameters;
        let mvv = m[(joint_index(0, 1), joint_index(0, 1))];
        assert_relative_eq!(mvv, p.reductions[1].powi(2) * p.rotor_axial, max_relative = 1e-3);
    }
}
