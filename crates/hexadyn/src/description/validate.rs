//! The relations between fields of a description, checked after reading it (each field's own
//! range is declared in [`super::tables`] and checked while reading): the legs, the pantograph
//! closure, the principal moments and masses of Table B.2, the reduction products of
//! Table 3.1, the ranges and the friction tables.

use std::collections::BTreeSet;

use super::tables::{RigidBodyTable, RobotDescription};
use super::values::{Interval, Measured, PerLegMaybe};
use crate::fields::{Ctx, Result};
use crate::hexapod::LEG_COUNT;

/// `v` within `rel` of `target`; `what` says where the target comes from.
fn close(c: &Ctx, field: &str, v: f64, target: f64, rel: f64, what: &str) -> Result<()> {
    let ok = (v - target).abs() <= rel * target.abs();
    c.check(ok, field, v, &format!("{target:.6} within {:.2} % ({what})", rel * 100.0))
}

/// min < max.
fn interval(c: &Ctx, field: &str, i: &Interval) -> Result<()> {
    c.finite(&format!("{field}.min"), i.min)?;
    c.finite(&format!("{field}.max"), i.max)?;
    if i.min >= i.max {
        return Err(c.err(&format!("{field}.min"), i.min, "out of range", format!("min < max (max = {})", i.max)));
    }
    Ok(())
}

/// The triangle inequality of the principal moments of a rigid body.
fn rigid_body(c: &Ctx, field: &str, b: &RigidBodyTable) -> Result<()> {
    let names = ["i_xx_kg_m2", "i_yy_kg_m2", "i_zz_kg_m2"];
    let m = b.principal_moments();
    for k in 0..3 {
        let (a, c2) = (m[(k + 1) % 3], m[(k + 2) % 3]);
        if m[k] > (a + c2) * (1.0 + 1e-9) {
            return Err(c.err(
                &format!("{field}.{}", names[k]),
                m[k],
                "violates the triangle inequality of principal moments",
                format!(
                    "a value <= {} + {} = {} ({} + {}; a rigid body needs each principal moment <= the sum of the other two)",
                    a,
                    c2,
                    a + c2,
                    names[(k + 1) % 3],
                    names[(k + 2) % 3]
                ),
            ));
        }
    }
    Ok(())
}

/// A mean and its standard deviation are both given or both `"-"`.
fn per_leg_maybe(c: &Ctx, field: &str, p: &PerLegMaybe) -> Result<()> {
    for (i, (mu, sigma)) in p.mu.iter().zip(&p.sigma).enumerate() {
        match (mu, sigma) {
            (Measured::Value(_), Measured::Missing) => {
                return Err(c.err(
                    &format!("{field}.sigma[{i}]"),
                    sigma,
                    "missing standard deviation",
                    "a number >= 0 where the mean is given (\"-\" only together with mu = \"-\")",
                ))
            }
            (Measured::Missing, Measured::Value(_)) => {
                return Err(c.err(
                    &format!("{field}.sigma[{i}]"),
                    sigma,
                    "standard deviation without a mean",
                    "\"-\" where mu is \"-\"",
                ))
            }
            _ => {}
        }
    }
    Ok(())
}

impl RobotDescription {
    pub(super) fn validate(&self, c: &Ctx) -> Result<()> {
        self.validate_legs(c)?;
        self.validate_geometry(c)?;
        self.validate_inertia(c)?;
        self.validate_reductions(c)?;
        self.validate_electrics(c)?;
        self.validate_ranges(c)?;
        self.validate_friction(c)
    }

    fn validate_legs(&self, c: &Ctx) -> Result<()> {
        if self.legs.len() != LEG_COUNT {
            return Err(c.err(
                "legs",
                format!("{} [[legs]] entries", self.legs.len()),
                "wrong number of legs",
                "exactly six [[legs]] tables with ids 0..5",
            ));
        }
        let mut seen = BTreeSet::new();
        for (i, leg) in self.legs.iter().enumerate() {
            if !seen.insert(leg.id) {
                return Err(c.err(&format!("legs[{i}].id"), leg.id, "duplicate leg id", "each id 0..5 exactly once"));
            }
        }
        for i in 0..LEG_COUNT {
            for j in 0..i {
                let d = (self.legs[i].angle_deg - self.legs[j].angle_deg).rem_euclid(360.0);
                if d.min(360.0 - d) < 1.0 {
                    return Err(c.err(
                        &format!("legs[{i}].angle_deg"),
                        self.legs[i].angle_deg,
                        "leg axes coincide",
                        format!(
                            "an angle at least 1 degree away from leg {} ({} deg)",
                            self.legs[j].id, self.legs[j].angle_deg
                        ),
                    ));
                }
            }
        }
        Ok(())
    }

    /// The pantograph of Table 2.1 closes (B-C-E-D a parallelogram) and its ratios are those of
    /// Eqs. B.1-B.2.
    fn validate_geometry(&self, c: &Ctx) -> Result<()> {
        let p = &self.geometry.pantograph;
        c.check(p.c_m < p.l_0_m, "geometry.pantograph.c_m", p.c_m, &format!("c = AB < l_0 = AC = {}", p.l_0_m))?;
        let bc = p.l_0_m - p.c_m;
        c.check(
            (p.l_2_m - bc).abs() <= 1e-6,
            "geometry.pantograph.l_2_m",
            p.l_2_m,
            &format!("l_2 = DE = BC = l_0 - c = {bc} (parallelogram B-C-E-D, Table 2.1)"),
        )?;
        c.check(p.l_3_m > p.l_1_m, "geometry.pantograph.l_3_m", p.l_3_m, &format!("CF > CE = l_1 = {}", p.l_1_m))?;
        let ratio = p.l_0_m / p.c_m;
        close(c, "geometry.pantograph.x_foot_per_q_h", p.x_foot_per_q_h, ratio, 0.05, "AC/AB, Eq. B.2")?;
        close(c, "geometry.pantograph.z_foot_per_q_v", p.z_foot_per_q_v, -(ratio - 1.0), 0.05, "-(AC/AB - 1), Eq. B.1")
    }

    /// Table B.2: principal moments of rigid bodies, the leg mass as the sum of its parts and
    /// the total mass.
    fn validate_inertia(&self, c: &Ctx) -> Result<()> {
        let m = &self.inertia;
        for (n, b) in [
            ("main_body", &m.main_body),
            ("chassis", &m.chassis),
            ("pantograph_upper", &m.pantograph_upper),
            ("pantograph_left", &m.pantograph_left),
            ("pantograph_lower", &m.pantograph_lower),
            ("pantograph_leg", &m.pantograph_leg),
        ] {
            rigid_body(c, &format!("inertia.{n}"), b)?;
        }
        let r = &m.rotor;
        c.check(
            r.i_axial_kg_m2 <= 2.0 * r.i_equatorial_kg_m2 * (1.0 + 1e-9),
            "inertia.rotor.i_axial_kg_m2",
            r.i_axial_kg_m2,
            &format!("<= 2 I_e = {} (triangle inequality)", 2.0 * r.i_equatorial_kg_m2),
        )?;
        let leg = self.leg_mass_kg();
        c.check(
            (m.leg_mass_kg - leg).abs() <= 5e-3,
            "inertia.leg_mass_kg",
            m.leg_mass_kg,
            &format!("m_1 + m_2 + m_3 + m_4 + m_5 + 3 m_rot = {leg:.4} within 0.005 kg (Table B.2)"),
        )?;
        close(c, "inertia.total_mass_kg", m.total_mass_kg, self.total_mass_kg(), 0.05, "m_0 + 6 m_leg")
    }

    /// Table 3.1: each global reduction is the product of its transmission elements.
    fn validate_reductions(&self, c: &Ctx) -> Result<()> {
        let r = &self.reductions;
        let k = &r.components;
        let sprocket = f64::from(k.sprocket_r_teeth[0]) / f64::from(k.sprocket_r_teeth[1]);
        close(c, "reductions.n_r", r.n_r, k.gearbox_r * sprocket, 0.005, "gearbox x sprocket, Table 3.1")?;
        close(c, "reductions.n_v_rad_per_m", r.n_v_rad_per_m, k.gearbox_v * k.ball_screw_rad_per_m, 0.005, "gearbox x ball screw")?;
        close(c, "reductions.n_h_rad_per_m", r.n_h_rad_per_m, k.gearbox_h * k.ball_screw_rad_per_m, 0.005, "gearbox x ball screw")
    }

    /// The motor's rotor inertia is the rotor of Table B.2; the dead band is in [0, supply).
    fn validate_electrics(&self, c: &Ctx) -> Result<()> {
        let m = &self.motor;
        close(
            c,
            "motor.rotor_inertia_g_cm2",
            m.rotor_inertia_kg_m2(),
            self.inertia.rotor.i_axial_kg_m2,
            0.01,
            "in kg m^2: J_r must match inertia.rotor.i_axial_kg_m2",
        )?;
        let d = &self.driver;
        c.check(
            d.dead_band_v >= 0.0 && d.dead_band_v < d.supply_voltage_v,
            "driver.dead_band_v",
            d.dead_band_v,
            &format!("a voltage in [0, supply_voltage_v = {})", d.supply_voltage_v),
        )
    }

    /// Table 5.2: min < max, and the pantograph closes over the whole range.
    fn validate_ranges(&self, c: &Ctx) -> Result<()> {
        let r = &self.joint_ranges;
        interval(c, "joint_ranges.q_r_deg", &r.q_r_deg)?;
        interval(c, "joint_ranges.q_v_m", &r.q_v_m)?;
        interval(c, "joint_ranges.q_h_m", &r.q_h_m)?;
        // The triangle A-B-D (sides c, l_1, k = AD = sqrt(q_v^2 + q_h^2)) must close over the
        // whole range (Eqs. 3.57-3.63).
        let p = &self.geometry.pantograph;
        let (lo, hi) = ((p.l_1_m - p.c_m).abs(), p.l_1_m + p.c_m);
        for (qv_name, qv) in [("min", r.q_v_m.min), ("max", r.q_v_m.max)] {
            for (qh_name, qh) in [("min", r.q_h_m.min), ("max", r.q_h_m.max)] {
                let k = qv.hypot(qh);
                if k <= lo || k >= hi {
                    return Err(c.err(
                        &format!("joint_ranges.q_v_m.{qv_name}"),
                        qv,
                        &format!("the pantograph cannot close at q_v = {qv}, q_h.{qh_name} = {qh} (AD = {k:.4} m)"),
                        format!("ranges with |l_1 - c| = {lo:.4} < sqrt(q_v^2 + q_h^2) < l_1 + c = {hi:.4} m at every corner"),
                    ));
                }
            }
        }
        let v = &r.identification_velocities;
        for (n, s) in [
            ("q_r_dot_deg_per_s", &v.q_r_dot_deg_per_s),
            ("q_v_dot_mm_per_s", &v.q_v_dot_mm_per_s),
            ("q_h_dot_mm_per_s", &v.q_h_dot_mm_per_s),
        ] {
            interval(c, &format!("joint_ranges.identification_velocities.{n}"), &Interval { min: s.min, max: s.max })?;
        }
        Ok(())
    }

    /// Table 5.4: each load once, the simulated load among them, a mean and its deviation
    /// given together; Table 5.5 likewise.
    fn validate_friction(&self, c: &Ctx) -> Result<()> {
        let f = &self.friction;
        let mut loads: Vec<f64> = Vec::new();
        for (i, s) in f.q_v.stiction.iter().enumerate() {
            let p = format!("friction.q_v.stiction[{i}]");
            if loads.contains(&s.load_kg) {
                return Err(c.err(&format!("{p}.load_kg"), s.load_kg, "duplicate load case", "each load_kg once"));
            }
            loads.push(s.load_kg);
            per_leg_maybe(c, &format!("{p}.tau_f_s_plus_n"), &s.tau_f_s_plus_n)?;
            per_leg_maybe(c, &format!("{p}.tau_f_s_minus_n"), &s.tau_f_s_minus_n)?;
        }
        if !loads.contains(&f.vertical_stiction_load_kg) {
            return Err(c.err(
                "friction.vertical_stiction_load_kg",
                f.vertical_stiction_load_kg,
                "no such load case",
                format!("one of the friction.q_v.stiction load_kg values {loads:?}"),
            ));
        }
        let a = &f.q_h.load_dependence;
        let p = "friction.q_h.load_dependence";
        per_leg_maybe(c, &format!("{p}.a_1_plus_n_per_kg"), &a.a_1_plus_n_per_kg)?;
        per_leg_maybe(c, &format!("{p}.a_1_minus_n_per_kg"), &a.a_1_minus_n_per_kg)
    }
}
