//! Failure reporting of the Newmark integrator: when the Newton-Raphson iteration of Eq. 3.10
//! cannot solve F(q''(t+h)) = 0 (Eq. 3.9), the error names the instant, the step and the offending
//! residual row with its coordinate and element.

mod common;

use common::*;
use hexadyn::sim::{Newmark, NewmarkOptions, SimError};

/// A residual row (Eq. 3.1) that turns NaN for t > 0.5 s ("leaky valve", coordinate "y"): the step is cut
/// down to the minimum step around t = 0.5 and `advance_to` returns SimError::NonFinite whose
/// message names t = 0.500000 s, the step size, the row's coordinate "y" and element "leaky valve"
/// (and not the healthy row "x"/"spring"). The state stays at the last good instant, just before 0.5.
#[test]
fn nan_residual_is_reported_with_time_step_and_row() {
    let mut sys = Faulty::new(Fault::NanAfter(0.5));
    let opts = NewmarkOptions { h_min: 1e-9, ..Default::default() };
    let mut nm = Newmark::new(&mut sys, 0.0, &[1.0, 0.5], &[0.0, 0.0], opts).unwrap();
    let err = nm.advance_to(&mut sys, 1.0).unwrap_err();
    let msg = err.to_string();
    eprintln!("NaN residual: {msg}\n{:?}", nm.stats());
    match &err {
        SimError::NonFinite { t, h, rows } => {
            assert!(*t > 0.5 && *t < 0.5 + 1e-8, "t = {t}");
            let h = h.expect("the step must be reported");
            assert!(h > 0.0 && h < 4e-9, "h = {h}");
            assert_eq!(rows.len(), 1, "{rows:?}");
            assert_eq!((rows[0].row, rows[0].coordinate.as_str(), rows[0].element.as_str()), (1, "y", "leaky valve"));
            assert!(rows[0].value.is_nan());
        }
        other => panic!("expected NonFinite, got {other:?}"),
    }
    assert!(msg.contains("t = 0.500000"), "{msg}");
    assert!(msg.contains("h = "), "{msg}");
    assert!(msg.contains("y") && msg.contains("leaky valve"), "{msg}");
    assert!(!msg.contains("spring"), "{msg}");
    let t = nm.state().t;
    assert!(t <= 0.5 && t > 0.5 - 1e-8, "state left at t = {t}");
    assert!(nm.stats().rejected_steps > 0);
}

/// A row with no real solution at all, y''² + y'' + 1 = 0 ("magic brake"), starting at t = 0.25:
/// Newton (Eq. 3.10) never converges, the step is divided down to h_min and `advance_to` returns
/// SimError::NewtonDiverged whose message names t = 0.250000 s, the step h, and the coordinate "y"
/// with its element "magic brake" as the largest residual (≥ 3/4, the minimum of y''² + y'' + 1).
/// This must hold down to the default h_min = 1e-10 s, where a correction of q'' measured in q
/// units (βh² Δq'') is ~1e-21 and only the relative test on q'' refuses it.
#[test]
fn impossible_equation_is_reported_with_time_step_and_row() {
    for h_min in [1e-8, NewmarkOptions::default().h_min] {
        let mut sys = Faulty::new(Fault::NoSolution);
        let opts = NewmarkOptions { h_min, ..Default::default() };
        let mut nm = Newmark::new(&mut sys, 0.25, &[1.0, 0.0], &[0.0, 0.0], opts).unwrap();
        let err = nm.advance_to(&mut sys, 1.0).unwrap_err();
        let msg = err.to_string();
        eprintln!("no solution (h_min {h_min:e}): {msg}\n{:?}", nm.stats());
        let SimError::NewtonDiverged { t, h, rows } = &err else { panic!("expected NewtonDiverged, got {err:?}") };
        assert_eq!(*t, 0.25);
        assert!(*h >= h_min && *h < 4.0 * h_min, "h = {h}");
        assert_eq!((rows[0].row, rows[0].coordinate.as_str(), rows[0].element.as_str()), (1, "y", "magic brake"));
        assert!(rows[0].value >= 0.75, "{rows:?}");
        assert!(msg.contains("t = 0.250000"), "{msg}");
        assert!(msg.contains(&format!("h = {h:.3e}")), "{msg}");
        assert!(msg.contains("row 1 (y, element magic brake)"), "{msg}");
        assert_eq!(nm.state().t, 0.25, "no step can have been accepted");
        assert_eq!(nm.stats().steps, 0);
    }
}

/// A residual (Eq. 3.1) that is NaN from the start is refused by `Newmark::new` (consistent initial
/// accelerations cannot be computed) with SimError::NonFinite naming the start time, the
/// coordinate and the element, and no step (there is none yet).
#[test]
fn nan_at_the_start_is_reported() {
    let mut sys = Faulty::new(Fault::NanAfter(-1.0));
    let err = match Newmark::new(&mut sys, 0.0, &[1.0, 0.0], &[0.0, 0.0], NewmarkOptions::default()) {
        Err(e) => e,
        Ok(_) => panic!("expected an error"),
    };
    let msg = err.to_string();
    assert!(matches!(err, SimError::NonFinite { t, h: None, .. } if t == 0.0), "{err:?}");
    assert!(msg.contains("t = 0.000000") && msg.contains("y") && msg.contains("leaky valve"), "{msg}");
}
