//! The hexapod's parameter sets ([`crate::hexapod`]) in SI units, built from a robot
//! description: the mechanics, the joint ranges and the leg kinematics.

use nalgebra::Vector3;

use super::{RigidBodyTable, RobotDescription};
use crate::hexapod::{Inertia, PantographJoint, JointLimits, LegKinematics, LegKinematicsError, MechanicsParameters, PantographGeometry};

impl MechanicsParameters {
    /// The mechanics of a robot description (SI units). Interpretations of the lost figures
    /// (NOTES.md), kept here in one place:
    /// - the q_r axis O_l lies at the height of the body centre of mass, at R_rot along the leg
    ///   direction;
    /// - the centre of gravity of link 0 lies at L_G0 from A along the link, that of the leg
    ///   (link 3) at x_G_leg from C; links 1 and 2 have theirs at mid-length;
    /// - all three rotors ride on the leg chassis (Eq. 3.69-3.71), the q_r rotor at L_x6 from
    ///   the body centre along the leg direction.
    pub fn from_description(d: &RobotDescription) -> Self {
        let g = &d.geometry;
        let pg = &g.pantograph;
        let inertia = |b: &RigidBodyTable| Inertia { mass: b.mass_kg, moments: Vector3::from(b.principal_moments()) };
        let i = &d.inertia;
        MechanicsParameters {
            pantograph: PantographGeometry { l0: pg.l_0_m, l1: pg.l_1_m, l2: pg.l_2_m, l3: pg.l_3_m, c: pg.c_m },
            leg_angles: d.leg_angles_rad(),
            r_rot: g.body.r_rot_m,
            chassis_cog: Vector3::new(g.chassis.l_x1_m, g.chassis.l_y1_m, g.chassis.l_z1_m),
            crossing_point: Vector3::new(g.chassis.l_xc_m, g.chassis.l_yc_m, g.chassis.l_zc_m),
            link_cog: [pg.l_g0_m, pg.l_1_m / 2.0, pg.l_2_m / 2.0, pg.x_g_leg_m],
            rotor_r_radius: g.actuators.l_x6_m,
            rotor_v: Vector3::new(g.actuators.l_x7_m, g.actuators.l_y7_m, g.actuators.l_z7_m),
            rotor_h: Vector3::new(g.actuators.l_x8_m, g.actuators.l_y8_m, g.actuators.l_z8_m),
            reductions: [d.reductions.n_r, d.reductions.n_v_rad_per_m, d.reductions.n_h_rad_per_m],
            body: inertia(&i.main_body),
            chassis: inertia(&i.chassis),
            links: [inertia(&i.pantograph_upper), inertia(&i.pantograph_left), inertia(&i.pantograph_lower), inertia(&i.pantograph_leg)],
            rotor_mass: i.rotor.mass_kg,
            rotor_axial: i.rotor.i_axial_kg_m2,
            rotor_equatorial: i.rotor.i_equatorial_kg_m2,
        }
    }
}

impl JointLimits {
    /// The ranges of a robot description ([`RobotDescription::joint_range`], SI).
    pub fn from_description(d: &RobotDescription) -> Self {
        let r = PantographJoint::ALL.map(|j| d.joint_range(j));
        JointLimits { lower: Vector3::new(r[0].0, r[1].0, r[2].0), upper: Vector3::new(r[0].1, r[1].1, r[2].1) }
    }
}

impl LegKinematics {
    /// Leg `leg` of a robot description.
    pub fn from_description(d: &RobotDescription, leg: usize) -> Result<Self, LegKinematicsError> {
        Self::new(&MechanicsParameters::from_description(d), JointLimits::from_description(d), leg)
    }

    /// The six legs of a robot description.
    pub fn hexapod_from_description(d: &RobotDescription) -> Result<[Self; 6], LegKinematicsError> {
        Self::hexapod(&MechanicsParameters::from_description(d), JointLimits::from_description(d))
    }
}
