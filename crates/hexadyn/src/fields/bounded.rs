//! Bounded fields: the constraint of a single field is declared with the field in the file
//! mirror and checked while deserializing.
//!
//! ```text
//! #[derive(Deserialize)]
//! struct MotorTable {
//!     #[serde(deserialize_with = "Positive::checked")]
//!     resistance_ohm: f64,
//! }
//! ```
//!
//! A value outside its bound fails with a [`Violation`] (value as read, problem, allowed) carried
//! through serde as the error message; the toml deserializer attaches the span of the value,
//! from which [`super::SpanIndex::serde_error`] finds the field path and line. A list is read
//! whole before its elements are checked, so that a list of the wrong length says so first; the
//! error of an element then carries the element's index (`mu[2]`).

use std::fmt;
use std::marker::PhantomData;

use serde::de::{self, DeserializeSeed, Deserializer, SeqAccess, Unexpected, Visitor};

/// Separates the parts of a [`Violation`] in a serde message (a character no field text has).
const SEPARATOR: char = '\u{1f}';

/// What is wrong with one value of a file: the parts of a field error the value itself knows
/// (the file, line and path come from its position, [`super::SpanIndex::serde_error`]).
#[derive(Clone, Debug, PartialEq)]
pub(crate) struct Violation {
    /// The value as read, e.g. `-0.334`, `NaN` or `an array of 5 values`.
    pub value: String,
    /// `out of range`, `not a finite number`, `wrong length`...
    pub problem: String,
    /// What would be accepted.
    pub allowed: String,
    /// The element of the array being read that is wrong, when the error is the array's.
    pub element: Option<usize>,
}

impl Violation {
    pub(crate) fn new(value: impl fmt::Display, problem: &str, allowed: &str) -> Self {
        Violation { value: value.to_string(), problem: problem.to_string(), allowed: allowed.to_string(), element: None }
    }

    /// The serde error that carries the violation.
    pub(crate) fn into_error<E: de::Error>(self) -> E {
        let element = self.element.map(|i| i.to_string()).unwrap_or_default();
        E::custom(format_args!("{SEPARATOR}{}{SEPARATOR}{}{SEPARATOR}{}{SEPARATOR}{element}", self.value, self.problem, self.allowed))
    }

    /// The violation carried by a serde error message, if it is one.
    pub(crate) fn parse(message: &str) -> Option<Violation> {
        let mut parts = message.strip_prefix(SEPARATOR)?.splitn(4, SEPARATOR);
        let (value, problem, allowed, element) = (parts.next()?, parts.next()?, parts.next()?, parts.next()?);
        Some(Violation { element: element.parse().ok(), ..Violation::new(value, problem, allowed) })
    }
}

/// A value of a file that a [`Bound`] can check: a number, or a number-like value such as a
/// measured value that may be missing.
pub(crate) trait Value: Sized + fmt::Display {
    /// What a value of the wrong type is told to be, as serde says it (`f64`, `u32`, ...).
    const EXPECTED: &'static str;
    fn from_f64<E: de::Error>(v: f64, expected: &dyn de::Expected) -> Result<Self, E>;
    fn from_i64<E: de::Error>(v: i64, expected: &dyn de::Expected) -> Result<Self, E>;
    fn from_u64<E: de::Error>(v: u64, expected: &dyn de::Expected) -> Result<Self, E>;
    fn from_str<E: de::Error>(v: &str, expected: &dyn de::Expected) -> Result<Self, E> {
        Err(E::invalid_type(Unexpected::Str(v), expected))
    }
    /// The number to check against the bound; None for a value that has none.
    fn number(&self) -> Option<f64>;
}

impl Value for f64 {
    const EXPECTED: &'static str = "f64";
    fn from_f64<E: de::Error>(v: f64, _: &dyn de::Expected) -> Result<Self, E> {
        Ok(v)
    }
    fn from_i64<E: de::Error>(v: i64, _: &dyn de::Expected) -> Result<Self, E> {
        Ok(v as f64)
    }
    fn from_u64<E: de::Error>(v: u64, _: &dyn de::Expected) -> Result<Self, E> {
        Ok(v as f64)
    }
    fn number(&self) -> Option<f64> {
        Some(*self)
    }
}

/// The unsigned integers of the files, with serde's own errors for a float or a negative
/// integer (`invalid type: floating point `500.5`, expected u32`).
macro_rules! unsigned_value {
    ($($t:ty),*) => {$(
        impl Value for $t {
            const EXPECTED: &'static str = stringify!($t);
            fn from_f64<E: de::Error>(v: f64, expected: &dyn de::Expected) -> Result<Self, E> {
                Err(E::invalid_type(Unexpected::Float(v), expected))
            }
            fn from_i64<E: de::Error>(v: i64, expected: &dyn de::Expected) -> Result<Self, E> {
                <$t>::try_from(v).map_err(|_| E::invalid_value(Unexpected::Signed(v), expected))
            }
            fn from_u64<E: de::Error>(v: u64, expected: &dyn de::Expected) -> Result<Self, E> {
                <$t>::try_from(v).map_err(|_| E::invalid_value(Unexpected::Unsigned(v), expected))
            }
            fn number(&self) -> Option<f64> {
                Some(*self as f64)
            }
        }
    )*};
}

unsigned_value!(u32, usize);

/// The allowed values of a single field, declared with the field: `#[serde(deserialize_with =
/// "Positive::checked")]`. A value outside the bound is `out of range` (`not a finite number`
/// if it is NaN or infinite), with [`Bound::ALLOWED`] as what is allowed.
pub(crate) trait Bound: Sized {
    /// What is allowed, as the error says it (`a finite number > 0`).
    const ALLOWED: &'static str;

    /// Whether a finite value is allowed.
    fn holds(v: f64) -> bool;

    /// serde `deserialize_with`: one value within the bound.
    fn checked<'de, T: Value, D: Deserializer<'de>>(d: D) -> Result<T, D::Error> {
        d.deserialize_any(Read::<T, Self>::new(true))
    }

    /// serde `deserialize_with`: a list of values, each within the bound (errors name the
    /// element, `field[i]`).
    fn list<'de, T: Value, D: Deserializer<'de>>(d: D) -> Result<Vec<T>, D::Error> {
        seq::<T, Self, D>(d, |_| None)
    }
}

/// Declares bounds, one a line: `Name = "what is allowed", |v| condition on v;` (with its doc
/// comment) makes the type `Name` whose [`Bound::holds`] is the condition.
macro_rules! bounds {
    ($($(#[$doc:meta])* $name:ident = $allowed:literal, |$v:ident| $holds:expr;)*) => {$(
        $(#[$doc])*
        pub(crate) enum $name {}

        impl $crate::fields::Bound for $name {
            const ALLOWED: &'static str = $allowed;
            fn holds($v: f64) -> bool {
                $holds
            }
        }
    )*};
}

pub(crate) use bounds;

bounds! {
    /// `> 0`.
    Positive = "a finite number > 0", |v| v > 0.0;
    /// `>= 0`.
    NonNegative = "a finite number >= 0", |v| v >= 0.0;
    /// Any finite number.
    Finite = "a finite number", |_v| true;
}

/// What is wrong with `value` under the bound `B`, if anything.
fn violation<T: Value, B: Bound>(value: &T) -> Option<Violation> {
    match value.number() {
        Some(x) if !x.is_finite() => Some(Violation::new(value, "not a finite number", B::ALLOWED)),
        Some(x) if !B::holds(x) => Some(Violation::new(value, "out of range", B::ALLOWED)),
        _ => None,
    }
}

/// The visitor of one value of type `T`, checked against `B` with `check`.
struct Read<T, B> {
    check: bool,
    types: PhantomData<(T, B)>,
}

impl<T: Value, B: Bound> Read<T, B> {
    fn new(check: bool) -> Self {
        Read { check, types: PhantomData }
    }

    fn checked<E: de::Error>(&self, value: T) -> Result<T, E> {
        match violation::<T, B>(&value) {
            Some(v) if self.check => Err(v.into_error()),
            _ => Ok(value),
        }
    }
}

impl<'de, T: Value, B: Bound> Visitor<'de> for Read<T, B> {
    type Value = T;

    fn expecting(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.write_str(T::EXPECTED)
    }

    fn visit_f64<E: de::Error>(self, v: f64) -> Result<T, E> {
        self.checked(T::from_f64(v, &self)?)
    }

    fn visit_i64<E: de::Error>(self, v: i64) -> Result<T, E> {
        self.checked(T::from_i64(v, &self)?)
    }

    fn visit_u64<E: de::Error>(self, v: u64) -> Result<T, E> {
        self.checked(T::from_u64(v, &self)?)
    }

    fn visit_str<E: de::Error>(self, v: &str) -> Result<T, E> {
        self.checked(T::from_str(v, &self)?)
    }
}

impl<'de, T: Value, B: Bound> DeserializeSeed<'de> for Read<T, B> {
    type Value = T;

    fn deserialize<D: Deserializer<'de>>(self, d: D) -> Result<T, D::Error> {
        d.deserialize_any(self)
    }
}

/// A list of values each within `B`, checked as a whole by `whole` (its length, say): a value
/// of the wrong type names its element (`field[i]`), then a `whole` error names the list, then
/// a value out of its bound names its element.
pub(crate) fn seq<'de, T: Value, B: Bound, D: Deserializer<'de>>(d: D, whole: fn(&[T]) -> Option<Violation>) -> Result<Vec<T>, D::Error> {
    struct List<T, B> {
        whole: fn(&[T]) -> Option<Violation>,
        bound: PhantomData<B>,
    }

    impl<'de, T: Value, B: Bound> Visitor<'de> for List<T, B> {
        type Value = Vec<T>;

        fn expecting(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
            f.write_str("a sequence")
        }

        fn visit_seq<A: SeqAccess<'de>>(self, mut seq: A) -> Result<Vec<T>, A::Error> {
            let mut values = Vec::new();
            while let Some(v) = seq.next_element_seed(Read::<T, B>::new(false))? {
                values.push(v);
            }
            if let Some(violation) = (self.whole)(&values) {
                return Err(violation.into_error());
            }
            match values.iter().enumerate().find_map(|(i, v)| Some((i, violation::<T, B>(v)?))) {
                Some((i, v)) => Err(Violation { element: Some(i), ..v }.into_error()),
                None => Ok(values),
            }
        }
    }

    d.deserialize_any(List::<T, B> { whole, bound: PhantomData })
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn violations_travel_through_serde_messages() {
        let v = Violation::new(-0.5, "out of range", "a finite number > 0");
        for v in [v.clone(), Violation { element: Some(3), ..v }] {
            let e: toml::de::Error = v.clone().into_error();
            assert_eq!(Violation::parse(e.message()), Some(v));
        }
        assert_eq!(Violation::parse("invalid type: string \"x\", expected f64"), None);
    }
}
