//! URDF import under abuse: 10 000 mutations of a valid serial hexapod (bytes cut, inserted or
//! replaced, numbers swapped for NaN, infinities, zeros, huge and negative values, elements
//! duplicated or dropped) never panic or hang; each is imported, and then builds its multibody
//! model, or is refused with one line naming the file.

use hexadyn::description::urdf::serial_hexapod_from_urdf;
use proptest::prelude::*;

mod mutations;
use mutations::{apply, mutation};

const URDF: &str = include_str!("data/random_hexapod.urdf");

#[test]
fn the_fixture_imports() {
    let robot = serial_hexapod_from_urdf(URDF, "hexapod.urdf").unwrap();
    assert_eq!(robot.mechanics().unwrap().model.coordinate_count(), 24);
}

proptest! {
    #![proptest_config(ProptestConfig { cases: 10_000, failure_persistence: None, ..ProptestConfig::default() })]
    #[test]
    fn mutated_urdf_never_panics(m in mutation(URDF)) {
        let text = apply(URDF, &m);
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
