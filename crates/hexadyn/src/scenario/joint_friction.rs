//! `[model.joint_friction]`: friction parameters identical for every leg, replacing the robot's
//! per-leg identification (Tables 5.3 and 5.5) in one scenario — the averaged friction of the
//! Monte Carlo runs of Section 6.5 (Table 6.7), or a what-if study.
//!
//! The keys, units and signs are documented with the file format in `docs/scenario-format.md`.
//!
//! Keys left out keep the robot's per-leg values. The signs are those of a physical friction
//! (a dry friction opposes the motion and grows with the load; a viscous slope is not negative),
//! which is also the rejection rule of the Monte Carlo draws (Section 6.5).

use serde::Deserialize;

use crate::description::{Measured, PerLeg, RobotDescription};
use crate::fields::{Ctx, DescriptionError};
use crate::hexapod::PantographJoint;

/// The raw `[model.joint_friction]` table.
#[derive(Deserialize, Default)]
#[serde(deny_unknown_fields)]
pub(super) struct RawJointFriction {
    q_r: Option<RawJointParameters>,
    q_v: Option<RawJointParameters>,
    q_h: Option<RawJointParameters>,
}

impl RawJointFriction {
    /// Whether no joint's friction is set.
    pub(super) fn is_empty(&self) -> bool {
        self.q_r.is_none() && self.q_v.is_none() && self.q_h.is_none()
    }
}

/// The parameters of one joint kind; all optional.
#[derive(Deserialize, Default)]
#[serde(deny_unknown_fields)]
struct RawJointParameters {
    tau_f_d_plus: Option<f64>,
    f_v_plus: Option<f64>,
    tau_f_d_minus: Option<f64>,
    f_v_minus: Option<f64>,
    a_2_plus: Option<f64>,
    a_1_plus: Option<f64>,
    a_2_minus: Option<f64>,
    a_1_minus: Option<f64>,
}

/// The sign a physical value has.
#[derive(Clone, Copy)]
enum Sign {
    NonNegative,
    NonPositive,
}

impl Sign {
    fn holds(self, v: f64) -> bool {
        match self {
            Sign::NonNegative => v >= 0.0,
            Sign::NonPositive => v <= 0.0,
        }
    }

    fn allowed(self, what: &str) -> String {
        match self {
            Sign::NonNegative => format!("a finite number >= 0 ({what})"),
            Sign::NonPositive => format!("a finite number <= 0 ({what}, minus sense)"),
        }
    }
}

impl RawJointFriction {
    /// Validates the table and writes its values into every leg of `robot`.
    pub(super) fn apply(&self, c: &Ctx, robot: &mut RobotDescription) -> Result<(), DescriptionError> {
        for (joint, raw) in [(PantographJoint::Rotation, &self.q_r), (PantographJoint::Vertical, &self.q_v), (PantographJoint::Horizontal, &self.q_h)] {
            if let Some(p) = raw {
                p.apply(c, joint, robot)?;
            }
        }
        Ok(())
    }
}

impl RawJointParameters {
    fn apply(&self, c: &Ctx, joint: PantographJoint, robot: &mut RobotDescription) -> Result<(), DescriptionError> {
        let path = format!("model.joint_friction.{}", joint.symbol());
        let field = |name: &str| format!("{path}.{name}");
        let (dry, viscous) = if joint.is_rotational() { ("Nm", "Nm s/rad") } else { ("N", "N s/m") };
        let checked = |name: &str, v: Option<f64>, sign: Sign, what: &str| -> Result<Option<f64>, DescriptionError> {
            match v {
                Some(v) => c.check(sign.holds(v), &field(name), v, &sign.allowed(what)).map(|()| Some(v)),
                None => Ok(None),
            }
        };
        let tau_f_d_plus = checked("tau_f_d_plus", self.tau_f_d_plus, Sign::NonNegative, &format!("dry friction tau_f_d^+, {dry}"))?;
        let f_v_plus = checked("f_v_plus", self.f_v_plus, Sign::NonNegative, &format!("viscous slope f_v^+, {viscous}"))?;
        let tau_f_d_minus = checked("tau_f_d_minus", self.tau_f_d_minus, Sign::NonPositive, &format!("dry friction tau_f_d^-, {dry}"))?;
        let f_v_minus = checked("f_v_minus", self.f_v_minus, Sign::NonNegative, &format!("viscous slope f_v^-, {viscous}"))?;
        let load = [("a_2_plus", self.a_2_plus, Sign::NonNegative, "a_2^+ of Eq. 5.12, N/kg^2"), ("a_1_plus", self.a_1_plus, Sign::NonNegative, "a_1^+ of Eq. 5.12, N/kg"), ("a_2_minus", self.a_2_minus, Sign::NonPositive, "a_2^- of Eq. 5.12, N/kg^2"), ("a_1_minus", self.a_1_minus, Sign::NonPositive, "a_1^- of Eq. 5.12, N/kg")];
        if joint != PantographJoint::Horizontal {
            if let Some((name, Some(v), _, _)) = load.iter().find(|l| l.1.is_some()) {
                return Err(c.err(&field(name), v, "no load dependence on this joint", "the load coefficients a_* only in [model.joint_friction.q_h] (Eq. 5.12 holds for the horizontal joints)"));
            }
        }
        let mut a = [None; 4];
        for (slot, (name, v, sign, what)) in a.iter_mut().zip(load) {
            *slot = checked(name, v, sign, what)?;
        }

        let f = &mut robot.friction;
        let tables: [&mut PerLeg; 4] = match joint {
            PantographJoint::Rotation => [&mut f.q_r.tau_f_d_plus_nm, &mut f.q_r.f_v_plus_nms, &mut f.q_r.tau_f_d_minus_nm, &mut f.q_r.f_v_minus_nms],
            PantographJoint::Vertical => [&mut f.q_v.tau_f_d_plus_n, &mut f.q_v.f_v_plus_ns_per_m, &mut f.q_v.tau_f_d_minus_n, &mut f.q_v.f_v_minus_ns_per_m],
            PantographJoint::Horizontal => [&mut f.q_h.tau_f_d_plus_n, &mut f.q_h.f_v_plus_ns_per_m, &mut f.q_h.tau_f_d_minus_n, &mut f.q_h.f_v_minus_ns_per_m],
        };
        for (table, value) in tables.into_iter().zip([tau_f_d_plus, f_v_plus, tau_f_d_minus, f_v_minus]) {
            if let Some(v) = value {
                table.mu.fill(v);
            }
        }
        let ld = &mut f.q_h.load_dependence;
        let [a_2_plus, a_1_plus, a_2_minus, a_1_minus] = a;
        for (table, value) in [(&mut ld.a_2_plus_n_per_kg2, a_2_plus), (&mut ld.a_2_minus_n_per_kg2, a_2_minus)] {
            if let Some(v) = value {
                table.mu.fill(v);
            }
        }
        for (table, value) in [(&mut ld.a_1_plus_n_per_kg, a_1_plus), (&mut ld.a_1_minus_n_per_kg, a_1_minus)] {
            if let Some(v) = value {
                table.mu.fill(Measured::Value(v));
            }
        }
        Ok(())
    }
}
