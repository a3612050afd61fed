//! Mutations of a valid input file for the fuzz tests (`urdf_fuzz.rs`,
//! `serial_description_fuzz.rs`).

use proptest::prelude::*;

/// The byte offsets of every number of `text` (after a quote, a space or a bracket: URDF
/// attribute values, TOML values and arrays).
pub fn number_spans(text: &str) -> Vec<(usize, usize)> {
    let bytes = text.as_bytes();
    let mut spans = Vec::new();
    let mut i = 0;
    while i < bytes.len() {
        let numeric = |b: u8| b.is_ascii_digit() || b == b'.' || b == b'-' || b == b'e';
        if numeric(bytes[i]) && (i == 0 || matches!(bytes[i - 1], b'"' | b' ' | b'[')) {
            let start = i;
            while i < bytes.len() && numeric(bytes[i]) {
                i += 1;
            }
            spans.push((start, i));
        } else {
            i += 1;
        }
    }
    spans
}

/// One change to a valid file.
#[derive(Clone, Debug)]
pub enum Mutation {
    Cut(usize, usize),
    Insert(usize, Vec<u8>),
    Number(usize, &'static str),
    DuplicateLine(usize),
    DropLine(usize),
}

/// Bytes cut, inserted or replaced, numbers swapped for NaN, infinities, zeros, huge and
/// negative values or garbage, lines duplicated or dropped, anywhere in `text`.
pub fn mutation(text: &str) -> impl Strategy<Value = Mutation> {
    let n = text.len();
    let lines = text.lines().count();
    let numbers = number_spans(text).len();
    let weird = prop::sample::select(vec!["NaN", "inf", "-inf", "0", "-0", "1e308", "-1e308", "1e-320", "-1", "", "1.2.3", "0x10", "99999999999999999999999"]);
    prop_oneof![
        (0..n, 0..200usize).prop_map(|(a, len)| Mutation::Cut(a, len)),
        (0..n, prop::collection::vec(prop::sample::select(b"<>/=\" abc0.9-e\n&;!?[],".to_vec()), 1..12)).prop_map(|(a, b)| Mutation::Insert(a, b)),
        (0..numbers, weird).prop_map(|(k, w)| Mutation::Number(k, w)),
        (0..lines).prop_map(Mutation::DuplicateLine),
        (0..lines).prop_map(Mutation::DropLine),
    ]
}

/// `text` changed by `m`.
pub fn apply(text: &str, m: &Mutation) -> String {
    let bytes = text.as_bytes();
    let out: Vec<u8> = match m {
        Mutation::Cut(a, len) => [&bytes[..*a], &bytes[(*a + len).min(bytes.len())..]].concat(),
        Mutation::Insert(a, b) => [&bytes[..*a], b.as_slice(), &bytes[*a..]].concat(),
        Mutation::Number(k, w) => {
            let (a, b) = number_spans(text)[*k];
            [&bytes[..a], w.as_bytes(), &bytes[b..]].concat()
        }
        Mutation::DuplicateLine(k) | Mutation::DropLine(k) => {
            let mut lines: Vec<&str> = text.lines().collect();
            let line = lines[*k];
            if matches!(m, Mutation::DropLine(_)) {
                lines.remove(*k);
            } else {
                lines.insert(*k, line);
            }
            lines.join("\n").into_bytes()
        }
    };
    String::from_utf8_lossy(&out).into_owned()
}

