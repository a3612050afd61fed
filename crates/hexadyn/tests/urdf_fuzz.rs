//! URDF import under abuse: 10 000 mutations of a valid serial hexapod (bytes cut, inserted or
//! replaced, numbers swapped for NaN, infinities, zeros, huge and negative values, elements
//! duplicated or dropped) never panic or hang; each is imported, and then builds its multibody
//! model, or is refused with one line naming the file.

use hexadyn::description::urdf::serial_hexapod_from_urdf;
use proptest::prelude::*;

const URDF: &str = include_str!("data/random_hexapod.urdf");

/// The byte offsets of every number of the file (attribute values split on spaces).
fn number_spans() -> Vec<(usize, usize)> {
    let bytes = URDF.as_bytes();
    let mut spans = Vec::new();
    let mut i = 0;
    while i < bytes.len() {
        let numeric = |b: u8| b.is_ascii_digit() || b == b'.' || b == b'-' || b == b'e';
        if numeric(bytes[i]) && (i == 0 || matches!(bytes[i - 1], b'"' | b' ')) {
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

#[derive(Clone, Debug)]
enum Mutation {
    Cut(usize, usize),
    Insert(usize, Vec<u8>),
    Number(usize, &'static str),
    DuplicateLine(usize),
    DropLine(usize),
}

fn mutation() -> impl Strategy<Value = Mutation> {
    let n = URDF.len();
    let lines = URDF.lines().count();
    let numbers = number_spans().len();
    let weird = prop::sample::select(vec!["NaN", "inf", "-inf", "0", "-0", "1e308", "-1e308", "1e-320", "-1", "", "1.2.3", "0x10", "99999999999999999999999"]);
    prop_oneof![
        (0..n, 0..200usize).prop_map(|(a, len)| Mutation::Cut(a, len)),
        (0..n, prop::collection::vec(prop::sample::select(b"<>/=\" abc0.9-e\n&;!?".to_vec()), 1..12)).prop_map(|(a, b)| Mutation::Insert(a, b)),
        (0..numbers, weird).prop_map(|(k, w)| Mutation::Number(k, w)),
        (0..lines).prop_map(Mutation::DuplicateLine),
        (0..lines).prop_map(Mutation::DropLine),
    ]
}

fn apply(m: &Mutation) -> String {
    let bytes = URDF.as_bytes();
    let out: Vec<u8> = match m {
        Mutation::Cut(a, len) => [&bytes[..*a], &bytes[(*a + len).min(bytes.len())..]].concat(),
        Mutation::Insert(a, b) => [&bytes[..*a], b.as_slice(), &bytes[*a..]].concat(),
        Mutation::Number(k, w) => {
            let (a, b) = number_spans()[*k];
            [&bytes[..a], w.as_bytes(), &bytes[b..]].concat()
        }
        Mutation::DuplicateLine(k) | Mutation::DropLine(k) => {
            let mut lines: Vec<&str> = URDF.lines().collect();
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

#[test]
fn the_fixture_imports() {
    let robot = serial_hexapod_from_urdf(URDF, "hexapod.urdf").unwrap();
    assert_eq!(robot.mechanics().unwrap().model.coordinate_count(), 24);
}

proptest! {
    #![proptest_config(ProptestConfig { cases: 10_000, failure_persistence: None, ..ProptestConfig::default() })]
    #[test]
    fn mutated_urdf_never_panics(m in mutation()) {
        let text = apply(&m);
        match serial_hexapod_from_urdf(&text, "fuzzed.urdf") {
            Ok(robot) => {
                robot.mechanics().expect("an imported robot builds its model");
            }
            Err(e) => {
                let line = e.to_string();
                prop_assert!(line.starts_with("fuzzed.urdf: ") && !line.contains('\n'), "{}", line);
            }
        }
    }
}
