//! The per-robot joint vocabulary: the names and kinds of a leg's three actuated joints.
//!
//! The thesis writes q = (X, Y, Z, Φ, Θ, Ψ, q_r, q_v, q_h per leg) (Eq. 3.51): AMRU5's joints are
//! one rotation and two nut translations. Another hexapod names its joints its own way (a
//! serial leg: `coxa`, `femur`, `tibia`, all revolute). Everything that names or measures a
//! joint (results columns and their units, plots, power tables, scenario motions) reads it from
//! the robot's [`LegJoints`], never from a fixed list. The six legs share it: joint `j` of leg
//! `leg` is coordinate [`super::joint_index`]`(leg, j)` and its columns are `{name}[{leg}]`.

use std::fmt;

/// What a joint's coordinate measures, which fixes its units.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash, serde::Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum JointKind {
    /// An angle (rad); its effort is a torque (Nm).
    Revolute,
    /// A length (m); its effort is a force (N) (the thesis' "joint torque" of a translation,
    /// footnote 4 of Chapter 3).
    Prismatic,
}

impl JointKind {
    /// `revolute` or `prismatic`, the URDF words.
    pub fn name(self) -> &'static str {
        match self {
            JointKind::Revolute => "revolute",
            JointKind::Prismatic => "prismatic",
        }
    }

    /// Picks the unit of a joint quantity: `units.0` for a revolute joint, `units.1` for a
    /// prismatic one (`kind.unit(("Nm", "N"))`).
    pub fn unit(self, units: (&'static str, &'static str)) -> &'static str {
        match self {
            JointKind::Revolute => units.0,
            JointKind::Prismatic => units.1,
        }
    }
}

/// Per-leg quantities of the results columns (`phase[2]`, `Fz[2]`, ...): a joint may not be
/// named like one of them, since its position column `{name}[{leg}]` would be theirs. The
/// robot's column test checks that every per-leg column outside the joints' is listed here.
pub const RESERVED_NAMES: [&str; 15] = [
    "phase",
    "touchdown",
    "foot_ref_x",
    "foot_ref_y",
    "foot_ref_z",
    "foot_x",
    "foot_y",
    "foot_z",
    "Fx",
    "Fy",
    "Fz",
    "Fn",
    "penetration",
    "F_gnd_est",
    "gnd_detected",
];

/// Why a joint vocabulary is refused.
#[derive(Clone, Debug, PartialEq, Eq, thiserror::Error)]
pub enum JointNameError {
    #[error("joint name {0:?} is not an identifier (a letter or _, then letters, digits or _)")]
    NotIdentifier(String),
    #[error("joint name {0:?} is a per-leg column of the results ({reserved})", reserved = RESERVED_NAMES.join(", "))]
    Reserved(String),
    #[error("joint names {0:?} and {1:?} would share results columns (one is the other's name joined by _)")]
    Overlapping(String, String),
}

/// The names and kinds of the three actuated joints of every leg, in the order of q.
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct LegJoints {
    names: [String; 3],
    kinds: [JointKind; 3],
}

impl LegJoints {
    /// Checks the names: identifiers, none a per-leg column ([`RESERVED_NAMES`]), and no name
    /// is another's joined by `_` (`q` and `q_dot`: the velocity column `q_dot[0]` of the first
    /// would be the position column of the second; `q` and `meas_q`: `i_meas_q[0]`).
    pub fn new(names: [String; 3], kinds: [JointKind; 3]) -> Result<Self, JointNameError> {
        for name in &names {
            let mut chars = name.chars();
            let head = chars.next().is_some_and(|c| c.is_ascii_alphabetic() || c == '_');
            if !head || !chars.all(|c| c.is_ascii_alphanumeric() || c == '_') {
                return Err(JointNameError::NotIdentifier(name.clone()));
            }
            if RESERVED_NAMES.contains(&name.as_str()) {
                return Err(JointNameError::Reserved(name.clone()));
            }
        }
        for a in &names {
            for b in &names {
                let joined = a.starts_with(&format!("{b}_")) || a.ends_with(&format!("_{b}"));
                if std::ptr::eq(a, b) || !(a == b || joined) {
                    continue;
                }
                return Err(JointNameError::Overlapping(b.clone(), a.clone()));
            }
        }
        Ok(LegJoints { names, kinds })
    }

    /// Name of joint `j` (0..3) of a leg.
    pub fn name(&self, j: usize) -> &str {
        &self.names[j]
    }

    /// Kind of joint `j` (0..3) of a leg.
    pub fn kind(&self, j: usize) -> JointKind {
        self.kinds[j]
    }

    /// The three names in the order of q.
    pub fn names(&self) -> impl Iterator<Item = &str> {
        self.names.iter().map(String::as_str)
    }

    /// Which joint of a leg is called `name`.
    pub fn position(&self, name: &str) -> Option<usize> {
        self.names.iter().position(|n| n == name)
    }

    /// Column name of a quantity of joint k = 3 leg + j: `{prefix}{name}{suffix}[{leg}]`
    /// (`column("u_", 4, "")` is `u_q_v[1]` on AMRU5).
    pub fn column(&self, prefix: &str, k: usize, suffix: &str) -> String {
        format!("{prefix}{}{suffix}[{}]", self.names[k % 3], k / 3)
    }

    /// Unit of a quantity of joint k = 3 leg + j: `units.0` if revolute, else `units.1`.
    pub fn unit(&self, k: usize, units: (&'static str, &'static str)) -> &'static str {
        self.kinds[k % 3].unit(units)
    }
}

impl fmt::Display for LegJoints {
    /// `q_r (revolute), q_v (prismatic), q_h (prismatic)`.
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        for (j, name) in self.names.iter().enumerate() {
            let sep = if j == 0 { "" } else { ", " };
            write!(f, "{sep}{name} ({})", self.kinds[j].name())?;
        }
        Ok(())
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn joints(names: [&str; 3]) -> Result<LegJoints, JointNameError> {
        LegJoints::new(names.map(String::from), [JointKind::Revolute; 3])
    }

    #[test]
    fn columns_and_units_follow_the_names_and_kinds() {
        let j = LegJoints::new(["q_r", "q_v", "q_h"].map(String::from), [JointKind::Revolute, JointKind::Prismatic, JointKind::Prismatic]).unwrap();
        assert_eq!(j.column("u_", 4, ""), "u_q_v[1]");
        assert_eq!(j.column("", 17, "_dot"), "q_h_dot[5]");
        assert_eq!((j.unit(3, ("rad", "m")), j.unit(5, ("rad", "m"))), ("rad", "m"));
        assert_eq!(j.position("q_h"), Some(2));
        assert_eq!(j.to_string(), "q_r (revolute), q_v (prismatic), q_h (prismatic)");
        let serial = joints(["coxa", "femur", "tibia"]).unwrap();
        assert_eq!(serial.column("tau_f_", 2, ""), "tau_f_tibia[0]");
        assert_eq!(serial.names().collect::<Vec<_>>(), ["coxa", "femur", "tibia"]);
    }

    #[test]
    fn names_that_would_share_a_column_are_refused() {
        assert_eq!(joints(["coxa", "coxa", "tibia"]), Err(JointNameError::Overlapping("coxa".into(), "coxa".into())));
        assert!(matches!(joints(["q", "q_dot", "x"]), Err(JointNameError::Overlapping(..))));
        assert!(matches!(joints(["q", "meas_q", "x"]), Err(JointNameError::Overlapping(..))));
        assert_eq!(joints(["phase", "a", "b"]), Err(JointNameError::Reserved("phase".into())));
        for bad in ["", "1a", "a b", "a[0]", "é"] {
            assert_eq!(joints([bad, "a", "b"]), Err(JointNameError::NotIdentifier(bad.into())), "{bad:?}");
        }
        assert!(joints(["_coxa", "femur2", "Tibia"]).is_ok());
    }
}
