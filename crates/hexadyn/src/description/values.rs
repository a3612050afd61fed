//! The value shapes of the description file (per-leg arrays, Gaussians, intervals, sweeps,
//! values the thesis may not give) and the bounds its single fields declare.
//!
//! A table field declares its bound with its shape: `#[serde(deserialize_with =
//! "Positive::per_leg")]` reads `{ mu = [six values > 0], sigma = [six values >= 0] }`.

use std::fmt;
use std::marker::PhantomData;

use serde::de::{self, Deserializer};
use serde::Deserialize;

use crate::fields::{bounds, seq, Bound, Finite, NonNegative, Positive, Value, Violation};
use crate::hexapod::LEG_COUNT;

// =============================================================================================
// Bounds of the description's fields (besides `Positive`, `NonNegative` and `Finite`)
// =============================================================================================

bounds! {
    /// A friction value of the minus sense (q_dot < 0).
    Negative = "a finite number < 0 (minus sense, q_dot < 0)", |v| v < 0.0;
    /// A load coefficient of the minus sense (Section 5.4).
    NonPositive = "a finite number <= 0 (minus sense)", |v| v <= 0.0;
    /// A direction of the body frame, degrees.
    LegAngle = "a finite angle in (-180, 180] degrees", |v| v > -180.0 && v <= 180.0;
    /// An angle of the rotational joint's range, degrees.
    HalfTurn = "a finite number in [-180, 180]", |v| (-180.0..=180.0).contains(&v);
    /// A body offset of Table B.1, metres.
    Offset = "a finite number in [-1, 1]", |v| (-1.0..=1.0).contains(&v);
    /// A phase margin, degrees.
    PhaseMargin = "a finite number in [0, 180]", |v| (0.0..=180.0).contains(&v);
    /// A factor of derating.
    Fraction = "a factor in (0, 1]", |v| v > 0.0 && v <= 1.0;
    /// A count.
    AtLeastOne = "an integer >= 1", |v| v >= 1.0;
    /// Teeth of a sprocket.
    ToothCount = "a tooth count >= 1", |v| v >= 1.0;
    /// Resolution of the PWM, bits.
    PwmBits = "an integer in [1, 32]", |v| (1.0..=32.0).contains(&v);
    /// The id of a `[[legs]]` entry (each once: checked with the other legs).
    LegId = "each id 0..5 exactly once", |v| v < LEG_COUNT as f64;
    /// A leg named in a list.
    LegIndex = "a leg id 0..5", |v| v < LEG_COUNT as f64;
}

// =============================================================================================
// Value shapes
// =============================================================================================

/// A closed interval [min, max] (read with its bound, `Shapes::interval`).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Interval {
    pub min: f64,
    pub max: f64,
}

/// min, max and increment of a sweep (all positive; min < max is checked with the other
/// fields).
#[derive(Clone, Copy, Debug, Deserialize, PartialEq)]
#[serde(deny_unknown_fields)]
pub struct Sweep {
    #[serde(deserialize_with = "Positive::checked")]
    pub min: f64,
    #[serde(deserialize_with = "Finite::checked")]
    pub max: f64,
    #[serde(deserialize_with = "Positive::checked")]
    pub increment: f64,
}

/// A Gaussian distribution N(mu, sigma^2) (read with the bound of mu, `Shapes::gaussian`).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Gaussian {
    pub mu: f64,
    pub sigma: f64,
}

/// Mean and standard deviation per leg, indexed by leg (read with the bound of the means,
/// `Shapes::per_leg`).
#[derive(Clone, Debug, PartialEq)]
pub struct PerLeg {
    pub mu: [f64; LEG_COUNT],
    pub sigma: [f64; LEG_COUNT],
}

/// Like [`PerLeg`], with `"-"` allowed where the thesis gives no value (`Shapes::per_leg_maybe`).
#[derive(Clone, Debug, PartialEq)]
pub struct PerLegMaybe {
    pub mu: [Measured; LEG_COUNT],
    pub sigma: [Measured; LEG_COUNT],
}

/// A number, or `"-"` for a value the thesis does not give.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum Measured {
    Value(f64),
    Missing,
}

impl Measured {
    pub fn value(self) -> Option<f64> {
        match self {
            Measured::Value(v) => Some(v),
            Measured::Missing => None,
        }
    }
}

impl fmt::Display for Measured {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            Measured::Value(v) => write!(f, "{v}"),
            Measured::Missing => f.write_str("\"-\""),
        }
    }
}

impl Value for Measured {
    const EXPECTED: &'static str = "a number or \"-\" (value not given by the thesis)";
    fn from_f64<E: de::Error>(v: f64, _: &dyn de::Expected) -> Result<Self, E> {
        Ok(Measured::Value(v))
    }
    fn from_i64<E: de::Error>(v: i64, _: &dyn de::Expected) -> Result<Self, E> {
        Ok(Measured::Value(v as f64))
    }
    fn from_u64<E: de::Error>(v: u64, _: &dyn de::Expected) -> Result<Self, E> {
        Ok(Measured::Value(v as f64))
    }
    fn from_str<E: de::Error>(v: &str, expected: &dyn de::Expected) -> Result<Self, E> {
        if v == "-" {
            Ok(Measured::Missing)
        } else {
            Err(E::invalid_value(de::Unexpected::Str(v), expected))
        }
    }
    fn number(&self) -> Option<f64> {
        self.value()
    }
}

// =============================================================================================
// Bounded shapes
// =============================================================================================

/// The shapes of the file with their values within a bound, for `deserialize_with`:
/// `Negative::per_leg` is a [`PerLeg`] whose means are `< 0` (standard deviations `>= 0`).
pub(crate) trait Shapes: Bound {
    /// One value per leg, each within the bound; another count is `wrong length`.
    fn per_leg_values<'de, T: Value, D: Deserializer<'de>>(d: D) -> Result<[T; LEG_COUNT], D::Error> {
        let values = seq::<T, Self, D>(d, |v| {
            (v.len() != LEG_COUNT).then(|| {
                Violation::new(format!("an array of {} values", v.len()), "wrong length", "exactly 6 values, one per leg 0..5")
            })
        })?;
        Ok(values.try_into().unwrap_or_else(|_| unreachable!("the length is checked")))
    }

    /// [`PerLeg`], means within the bound.
    fn per_leg<'de, D: Deserializer<'de>>(d: D) -> Result<PerLeg, D::Error> {
        PerLegOf::<f64, Self>::deserialize(d).map(|p| PerLeg { mu: p.mu, sigma: p.sigma })
    }

    /// [`PerLegMaybe`], the given means within the bound.
    fn per_leg_maybe<'de, D: Deserializer<'de>>(d: D) -> Result<PerLegMaybe, D::Error> {
        PerLegOf::<Measured, Self>::deserialize(d).map(|p| PerLegMaybe { mu: p.mu, sigma: p.sigma })
    }

    /// [`Gaussian`], mean within the bound.
    fn gaussian<'de, D: Deserializer<'de>>(d: D) -> Result<Gaussian, D::Error> {
        GaussianOf::<Self>::deserialize(d).map(|g| Gaussian { mu: g.mu, sigma: g.sigma })
    }

    /// [`Interval`], both ends within the bound (min < max is checked with the other fields).
    fn interval<'de, D: Deserializer<'de>>(d: D) -> Result<Interval, D::Error> {
        IntervalOf::<Self>::deserialize(d).map(|i| Interval { min: i.min, max: i.max })
    }
}

impl<B: Bound> Shapes for B {}

// The bounded forms of the shapes, which serde's messages name like the shapes ("expected
// struct PerLeg"); `B` is the bound of the means or of the interval ends.

/// [`PerLeg`] (`T = f64`) or [`PerLegMaybe`] (`T = Measured`).
#[derive(Deserialize)]
#[serde(expecting = "struct PerLeg", deny_unknown_fields, bound = "T: Value")]
struct PerLegOf<T, B: Bound> {
    #[serde(deserialize_with = "B::per_leg_values")]
    mu: [T; LEG_COUNT],
    #[serde(deserialize_with = "NonNegative::per_leg_values")]
    sigma: [T; LEG_COUNT],
    #[serde(skip)]
    bound: PhantomData<B>,
}

#[derive(Deserialize)]
#[serde(expecting = "struct Gaussian", deny_unknown_fields, bound = "")]
struct GaussianOf<B: Bound> {
    #[serde(deserialize_with = "B::checked")]
    mu: f64,
    #[serde(deserialize_with = "NonNegative::checked")]
    sigma: f64,
    #[serde(skip)]
    bound: PhantomData<B>,
}

#[derive(Deserialize)]
#[serde(expecting = "struct Interval", deny_unknown_fields, bound = "")]
struct IntervalOf<B: Bound> {
    #[serde(deserialize_with = "B::checked")]
    min: f64,
    #[serde(deserialize_with = "B::checked")]
    max: f64,
    #[serde(skip)]
    bound: PhantomData<B>,
}
