//! Helpers shared by the unit tests of the physical elements.

use rand::SeedableRng;
use rand_chacha::ChaCha8Rng;

/// Reproducible random generator for the finite-difference tests.
pub fn rng(seed: u64) -> ChaCha8Rng {
    ChaCha8Rng::seed_from_u64(seed)
}

/// Central finite difference (g(x + h) - g(x - h)) / 2h.
pub fn central(g: impl Fn(f64) -> f64, x: f64, h: f64) -> f64 {
    (g(x + h) - g(x - h)) / (2.0 * h)
}

/// Round-off bound of a central difference of a function of magnitude `value` with step `h`.
pub fn noise(value: f64, h: f64) -> f64 {
    1e3 * f64::EPSILON * value.abs() / h
}

/// Asserts |analytic - numeric| <= rel · max(|analytic|, |numeric|) + abs, naming the partial.
#[track_caller]
pub fn assert_partial(what: &str, analytic: f64, numeric: f64, rel: f64, abs: f64) {
    let bound = rel * analytic.abs().max(numeric.abs()) + abs;
    assert!(
        (analytic - numeric).abs() <= bound,
        "{what}: analytic {analytic:e} vs finite difference {numeric:e} (tolerance {bound:e})"
    );
}
