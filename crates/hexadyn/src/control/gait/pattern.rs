//! Periodic gait patterns (thesis Section 7.1.2, Fig. 7.4-7.5) and the foot cycle phases
//! (Section 7.5, 7.6, Fig. 7.12, 7.22-7.23).

/// A periodic gait: duty factor β and the local phase of each leg at the gait's time origin
/// (Eq. 7.1: φ = (t − n_step T)/T; support starts at φ = 0, swing at φ = β).
#[derive(Clone, Debug, PartialEq)]
pub struct GaitPattern {
    pub name: String,
    pub beta: f64,
    pub offsets: [f64; 6],
}

/// Which gait, as named in scenario files.
#[derive(Clone, Copy, Debug, PartialEq, Eq, serde::Deserialize, serde::Serialize)]
#[serde(rename_all = "snake_case")]
pub enum GaitKind {
    Tripod,
    Wave,
    EqualPhase,
}

impl GaitPattern {
    /// A pattern from the instants (fractions of the cycle) at which each leg starts its swing.
    pub fn from_swing_starts(name: &str, beta: f64, swing_starts: [f64; 6]) -> Self {
        GaitPattern { name: name.into(), beta, offsets: swing_starts.map(|s| (beta - s).rem_euclid(1.0)) }
    }
    /// Tripod gait (Fig. 7.4): tripods {0, 3, 4} and {1, 2, 5} alternate, β = 1/2.
    pub fn tripod() -> Self {
        Self::from_swing_starts("tripod", 0.5, [0.5, 0.0, 0.0, 0.5, 0.5, 0.0])
    }
    /// Forward wave gait (Fig. 7.5(a)): on each side the swings run from rear to front, one
    /// every 1 − β of the cycle; contralateral legs are half a cycle apart (β = 3/4 gives
    /// 4 → 2 → 0 and 5 → 3 → 1 with legs 1 and 4 together).
    pub fn wave(beta: f64) -> Self {
        let d = 1.0 - beta;
        let left = [2.0 * d, d, 0.0]; // legs 0, 2, 4
        let starts = [left[0], left[0] + 0.5, left[1], left[1] + 0.5, left[2], left[2] + 0.5].map(|s: f64| s.rem_euclid(1.0));
        Self::from_swing_starts("wave", beta, starts)
    }
    /// Forward full-cycle equal-phase gait (Fig. 7.5(b)): the six swings start evenly, one every
    /// sixth of the cycle, rear to front on each side, sides half a cycle apart.
    pub fn equal_phase(beta: f64) -> Self {
        // Order of swing starts: 4, 1, 2, 5, 0, 3.
        let sixth = 1.0 / 6.0;
        Self::from_swing_starts("equal phase", beta, [4.0 * sixth, sixth, 2.0 * sixth, 5.0 * sixth, 0.0, 3.0 * sixth])
    }
    pub fn of(kind: GaitKind, beta: f64) -> Self {
        match kind {
            GaitKind::Tripod => Self::tripod(),
            GaitKind::Wave => Self::wave(beta),
            GaitKind::EqualPhase => Self::equal_phase(beta),
        }
    }
    /// Local phase of `leg` at time `t` after the gait origin (Eq. 7.1).
    pub fn phase(&self, leg: usize, t: f64, period: f64) -> f64 {
        (t / period + self.offsets[leg]).rem_euclid(1.0)
    }
}

/// Phase of a foot within its cycle.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum FootPhase {
    /// On the ground propelling the body (including the PEP and AEP overlaps).
    Support,
    /// Lifting with the support's horizontal motion (enhanced cycle).
    Takeoff,
    /// In the air towards the AEP.
    Swing,
    /// Going down with the support's horizontal motion already begun (enhanced cycle).
    Landing,
}

impl FootPhase {
    /// The four phases in the order of a cycle's foot phase codes (0 support, 1 takeoff,
    /// 2 swing, 3 landing).
    pub const ALL: [FootPhase; 4] = [FootPhase::Support, FootPhase::Takeoff, FootPhase::Swing, FootPhase::Landing];

    /// The phase's name as in the thesis (Section 7.6): `support`, `takeoff`, `swing`, `landing`.
    pub fn name(self) -> &'static str {
        match self {
            FootPhase::Support => "support",
            FootPhase::Takeoff => "takeoff",
            FootPhase::Swing => "swing",
            FootPhase::Landing => "landing",
        }
    }

    /// Phase code of the `phase[l]` columns and gait diagrams: the index in [`FootPhase::ALL`]
    /// (0 support, 1 takeoff, 2 swing, 3 landing).
    pub fn code(self) -> f64 {
        FootPhase::ALL.iter().position(|&p| p == self).expect("every phase is in ALL") as f64
    }

    pub fn on_ground(self) -> bool {
        self == FootPhase::Support
    }
}

/// The foot cycle: plain (Fig. 7.12) or enhanced with overlap, takeoff and landing (Fig. 7.22).
#[derive(Clone, Copy, Debug, PartialEq, serde::Deserialize, serde::Serialize)]
#[serde(tag = "kind", rename_all = "snake_case", deny_unknown_fields)]
pub enum FootCycle {
    Plain,
    /// Δφ: the overlap fraction (Table 6.2: 5 %).
    Enhanced { overlap: f64 },
}

impl FootCycle {
    /// Phase of the foot at local phase φ for duty factor β (Section 7.6): support up to
    /// β + Δφ/2 (PEP overlap), takeoff to β + 2Δφ, swing to 1 − 2Δφ, landing to 1 − Δφ/2, then
    /// the AEP overlap on the ground.
    pub fn phase(&self, phi: f64, beta: f64) -> FootPhase {
        match *self {
            FootCycle::Plain => {
                if phi < beta {
                    FootPhase::Support
                } else {
                    FootPhase::Swing
                }
            }
            FootCycle::Enhanced { overlap: d } => {
                if phi < beta + d / 2.0 || phi >= 1.0 - d / 2.0 {
                    FootPhase::Support
                } else if phi < beta + 2.0 * d {
                    FootPhase::Takeoff
                } else if phi < 1.0 - 2.0 * d {
                    FootPhase::Swing
                } else {
                    FootPhase::Landing
                }
            }
        }
    }
    /// Fraction of the cycle spent in the horizontal swing: (1 − β) T (Eq. 7.26) or
    /// (1 − (β + 4Δφ)) T (Eq. 7.31).
    pub fn swing_fraction(&self, beta: f64) -> f64 {
        match *self {
            FootCycle::Plain => 1.0 - beta,
            FootCycle::Enhanced { overlap } => 1.0 - (beta + 4.0 * overlap),
        }
    }
    /// Fraction of the cycle over which the stroke is centred on C: β (Eq. 7.24) or β + 4Δφ
    /// (Eq. 7.30).
    pub fn support_fraction(&self, beta: f64) -> f64 {
        1.0 - self.swing_fraction(beta)
    }
    /// Start of the horizontal swing and of the vertical lift, as phases.
    pub fn swing_start(&self, beta: f64) -> f64 {
        match *self {
            FootCycle::Plain => beta,
            FootCycle::Enhanced { overlap } => beta + 2.0 * overlap,
        }
    }
    /// Duration (cycle fraction) of the takeoff and of the landing.
    pub fn transition_fraction(&self) -> f64 {
        match *self {
            FootCycle::Plain => 0.0,
            FootCycle::Enhanced { overlap } => 1.5 * overlap,
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn swinging(p: &GaitPattern, cycle: FootCycle, t: f64) -> Vec<usize> {
        (0..6).filter(|&l| !cycle.phase(p.phase(l, t, 1.0), p.beta).on_ground()).collect()
    }

    #[test]
    fn tripod_alternates_the_two_tripods_with_overlaps() {
        let p = GaitPattern::tripod();
        let enhanced = FootCycle::Enhanced { overlap: 0.05 };
        assert_eq!(swinging(&p, enhanced, 0.3), vec![1, 2, 5]);
        assert_eq!(swinging(&p, enhanced, 0.8), vec![0, 3, 4]);
        // Overlap: all six feet down around the switch.
        assert!(swinging(&p, enhanced, 0.01).is_empty());
        assert!(swinging(&p, enhanced, 0.51).is_empty());
        // Phase windows of Section 7.6 for a leg starting its support at 0.
        let c = enhanced;
        assert_eq!(c.phase(0.52, 0.5), FootPhase::Support);
        assert_eq!(c.phase(0.55, 0.5), FootPhase::Takeoff);
        assert_eq!(c.phase(0.75, 0.5), FootPhase::Swing);
        assert_eq!(c.phase(0.92, 0.5), FootPhase::Landing);
        assert_eq!(c.phase(0.98, 0.5), FootPhase::Support);
        assert!((c.swing_fraction(0.5) - 0.3).abs() < 1e-15);
    }

    /// Wave and equal-phase gaits with β = 3/4 never lift more than two legs, never two
    /// neighbours (circuit 0-1-3-5-4-2-0), and every leg is on the ground 3/4 of the time.
    #[test]
    fn wave_and_equal_phase_keep_four_feet_down() {
        let neighbours = [(0, 1), (1, 3), (3, 5), (5, 4), (4, 2), (2, 0)];
        for p in [GaitPattern::wave(0.75), GaitPattern::equal_phase(0.75)] {
            let mut down_time = [0usize; 6];
            for i in 0..1000 {
                let t = i as f64 / 1000.0;
                let s = swinging(&p, FootCycle::Plain, t);
                assert!(s.len() <= 2, "{}: {s:?} at {t}", p.name);
                for (a, b) in neighbours {
                    assert!(!(s.contains(&a) && s.contains(&b)), "{}: neighbours {a}, {b} swing at {t}", p.name);
                }
                for l in 0..6 {
                    if !s.contains(&l) {
                        down_time[l] += 1;
                    }
                }
            }
            assert!(down_time.iter().all(|&d| d == 750), "{}: {down_time:?}", p.name);
        }
    }
}
