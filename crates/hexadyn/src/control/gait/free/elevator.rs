//! The elevator reflex of the swing (beyond the thesis, issue 11): a swinging foot stopped by an
//! obstacle rises and goes on.
//!
//! Section 7.7.3 keeps the foot at the height of the end of the takeoff through the swing
//! ("this supposes that the takeoff has given a foot clearance high enough to avoid
//! obstacles"): a riser higher than the lift stops the foot, which then lands at its base and
//! leaves the leg behind the step. The walking insects (the stick insect's elevator reflex) and
//! the hexapods modelled on them answer a resistance to the forward motion of the swing by
//! lifting the foot and retrying. AMRU5 has no foot sensors; the resistance shows in its motor
//! currents: the ground torques of the three joints estimated from the currents and the
//! encoders (Section 5.6.2, Eq. 5.14-5.16), turned into the force on the foot by the leg
//! Jacobian (Eq. 5.20, the whole J^{−T} where Eq. 5.22 keeps its vertical row), push the foot
//! back against the direction of its swing. (The encoders alone do not tell it: the foot pushed
//! against a riser pushes the body back on its compliant support rather than falling behind its
//! reference, and a long swing lags its reference by centimetres on flat ground.)
//!
//! INTERPRETATION (the thesis is silent): the resistance is the estimated foot force against the
//! horizontal swing direction; when it stays above the threshold of the landing detection
//! (`gait.free.landing_threshold_n`, 40 N on AMRU5, the same estimator on the joints that drive
//! the swing) for the settling time of
//! the 3 Hz filters ([`SETTLING_TIME_CONSTANTS`], counted once the joints have swung for that
//! time: the reversal of the joints at the start of the swing reads as up to 65 N for about
//! 0.15 s on flat ground, a riser pushes as long as the swing goes on), the foot backs off by
//! [`ELEVATOR_RETREAT`], rises by the lift of the takeoff at the takeoff's speed (as high as the
//! leg reaches), and swings on from there to the AEP in the swing time that was left. Repeated
//! until the foot passes or the leg's reach is exhausted. It needs a landing detector that
//! estimates the foot forces (`landing = "current"`); with the simulated normal forces of the
//! thesis' simulation mode the swing is the thesis' one.
//!
//! INTERPRETATION (issue 37): an obstacle the leg cannot rise over (the foot backed off and
//! raised by half the lift would leave its reach) ends the swing: the foot backs off by
//! [`ELEVATOR_RETREAT`] and lands there, in front of the obstacle, a short step. The swing
//! going on blocked pushed the body back through the foot for the rest of the swing time: on
//! boulders of 3 cm RMS at the thesis' 10.5 cm lift (seed 5), up to 123 N for 2.0 s, the support
//! feet slid 20 cm, the body turned 10° and stayed 12 cm behind its desired pose, where the feet
//! that then landed were short of their footholds and lifted again for good (measured
//! 2026-11-30; the class went from 55 to 100 % success, `benches/src/bin/terrain_classes.rs`).

use nalgebra::Vector3;

#[cfg(doc)]
use crate::control::SETTLING_TIME_CONSTANTS;

/// How far the foot backs off from the obstacle before it rises (m): the foot radius of AMRU5
/// (2 cm), so that the foot does not rub up the riser face under the PI's push.
pub const ELEVATOR_RETREAT: f64 = 0.02;

/// The resistance to the swing: the component of the foot force `force` against the horizontal
/// swing direction `direction` (both leg frame; the direction need not be unit), or 0 without a
/// horizontal direction.
pub fn resistance(force: &Vector3<f64>, direction: &Vector3<f64>) -> f64 {
    let u = Vector3::new(direction.x, direction.y, 0.0);
    let n = u.norm();
    if n > 0.0 {
        -force.dot(&u) / n
    } else {
        0.0
    }
}

/// The foot reference from which the reflex rises: the measured foot backed off by
/// [`ELEVATOR_RETREAT`] against the swing direction, at the reference's height.
pub fn retreat(reference: &Vector3<f64>, measured: &Vector3<f64>, direction: &Vector3<f64>) -> Vector3<f64> {
    let u = Vector3::new(direction.x, direction.y, 0.0).try_normalize(0.0).unwrap_or_else(Vector3::zeros);
    let p = measured - u * ELEVATOR_RETREAT;
    Vector3::new(p.x, p.y, reference.z)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_resistance_is_the_force_against_the_swing() {
        let d = Vector3::new(3.0, 4.0, 7.0);
        // 50 N straight back against the swing (and 100 N up): 50 N of resistance.
        let f = Vector3::new(-30.0, -40.0, 100.0);
        assert!((resistance(&f, &d) - 50.0).abs() < 1e-12);
        // Sideways or pulling forward is no resistance.
        assert!(resistance(&Vector3::new(-40.0, 30.0, 0.0), &d).abs() < 1e-12);
        assert!(resistance(&-f, &d) < 0.0);
        assert_eq!(resistance(&f, &Vector3::z()), 0.0);
    }

    #[test]
    fn the_retreat_backs_off_from_the_measured_foot_at_the_reference_height() {
        let m = Vector3::new(0.1, 0.2, -0.4);
        let r = Vector3::new(0.5, 0.2, -0.3);
        let p = retreat(&r, &m, &Vector3::new(2.0, 0.0, 0.0));
        assert!((p - Vector3::new(0.1 - ELEVATOR_RETREAT, 0.2, -0.3)).norm() < 1e-12);
    }
}
