//! What went wrong in a walk, and when (issue 37): the longest stretch of each condition a
//! healthy walk should never hold for long, accumulated control instant by control instant for
//! the summary (`hexadyn.health` turns them into warnings).

use crate::control::gait::pattern::FootPhase;

/// The longest stretch of time a condition held (s), when it began, and whether it still held
/// at the last instant.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct Episode {
    /// Start of the stretch in progress.
    since: Option<f64>,
    /// The longest stretch: its duration (s) and its start (s).
    pub longest: Option<(f64, f64)>,
}

impl Episode {
    /// The condition at the control instant `t`. A stretch lasts from the first instant it holds
    /// to the last one.
    pub fn observe(&mut self, t: f64, holds: bool) {
        if !holds {
            self.since = None;
            return;
        }
        let since = *self.since.get_or_insert(t);
        if self.longest.is_none_or(|(d, _)| t - since > d) {
            self.longest = Some((t - since, since));
        }
    }

    /// The condition holds at the last instant.
    pub fn ongoing(&self) -> bool {
        self.since.is_some()
    }
}

/// The share of the robot's weight above which a foot in its takeoff or swing counts as
/// carrying load.
///
/// INTERPRETATION: issue 37's criterion for AMRU5, no foot in takeoff or swing carrying more
/// than 50 N for more than 0.3 s, is 15 % of its 34 kg weight (333 N); a foot that unloads as
/// its takeoff begins drops below it within a few control periods, one that the body leans on
/// (its neighbours unloaded) does not.
pub const AIRBORNE_LOAD_SHARE: f64 = 0.15;

/// The walk's episodes: the free gait's deadlocks, fewer than three loaded feet, and a foot
/// carrying load while it should be in the air.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct WalkEpisodes {
    pub deadlock: Episode,
    pub support_loss: Episode,
    pub airborne_load: Episode,
}

impl WalkEpisodes {
    /// One control instant: `phases` the foot phase codes ([`FootPhase::code`]), `normal` the
    /// normal force on each foot (N), `weight` the robot's weight (N), `deadlock` the free
    /// gait's flag.
    pub fn observe(&mut self, t: f64, phases: &[f64; 6], normal: &[f64; 6], weight: f64, deadlock: bool) {
        let airborne = [FootPhase::Takeoff.code(), FootPhase::Swing.code()];
        self.deadlock.observe(t, deadlock);
        self.support_loss.observe(t, normal.iter().filter(|&&f| f > 0.0).count() < 3);
        self.airborne_load.observe(t, (0..6).any(|l| airborne.contains(&phases[l]) && normal[l] > AIRBORNE_LOAD_SHARE * weight));
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_longest_stretch_and_its_start() {
        let mut e = Episode::default();
        let on = [false, true, true, false, true, true, true, true, false, true];
        for (k, &holds) in on.iter().enumerate() {
            e.observe(0.1 * k as f64, holds);
        }
        let (d, start) = e.longest.unwrap();
        assert!((d - 0.3).abs() < 1e-12 && (start - 0.4).abs() < 1e-12);
        assert!(e.ongoing());
        assert_eq!(Episode::default().longest, None);
    }

    #[test]
    fn walk_episodes() {
        let mut w = WalkEpisodes::default();
        let swing = FootPhase::Swing.code();
        let support = FootPhase::Support.code();
        // Leg 0 swings while carrying 20 % of the weight; then two feet only are loaded.
        w.observe(0.0, &[swing, support, support, support, support, support], &[200.0, 1.0, 1.0, 1.0, 1.0, 1.0], 1000.0, false);
        w.observe(0.01, &[swing, support, support, support, support, support], &[200.0, 1.0, 0.0, 0.0, 0.0, 0.0], 1000.0, true);
        w.observe(0.02, &[swing, support, support, support, support, support], &[100.0, 1.0, 1.0, 0.0, 0.0, 0.0], 1000.0, false);
        assert_eq!(w.airborne_load.longest, Some((0.01, 0.0)));
        assert_eq!(w.support_loss.longest, Some((0.0, 0.01)));
        assert_eq!(w.deadlock.longest, Some((0.0, 0.01)));
        assert!(!w.deadlock.ongoing() && !w.airborne_load.ongoing());
    }
}
