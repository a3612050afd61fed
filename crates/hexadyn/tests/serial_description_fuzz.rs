//! The serial robot description under abuse: 10 000 mutations of the shipped PhantomX
//! description (bytes cut, inserted or replaced, numbers swapped for NaN, infinities, zeros,
//! huge and negative values, lines duplicated or dropped) never panic or hang; each is read,
//! and then gives its model parts and leg kinematics, or is refused with one line naming the
//! file.

use hexadyn::description::{Robot, PHANTOMX_TOML};
use hexadyn::hexapod::SerialLegKinematics;
use hexadyn::robot::model::FrictionModel;
use proptest::prelude::*;

mod mutations;
use mutations::{apply, mutation};

proptest! {
    #![proptest_config(ProptestConfig { cases: 10_000, failure_persistence: None, ..ProptestConfig::default() })]
    #[test]
    fn a_mutated_description_never_panics(m in mutation(PHANTOMX_TOML)) {
        let text = apply(PHANTOMX_TOML, &m);
        match Robot::from_str(&text, "fuzzed.toml") {
            Ok(Robot::Serial(robot)) => {
                for friction in [FrictionModel::None, FrictionModel::DryViscous, FrictionModel::LuGre] {
                    let _parts = robot.parts(&robot.model_options(friction));
                }
                SerialLegKinematics::hexapod(&robot.hexapod.legs).expect("validated joint ranges give leg kinematics");
            }
            Ok(Robot::Pantograph(_)) => prop_assert!(false, "a serial description read as a pantograph"),
            Err(e) => {
                let line = e.to_string();
                prop_assert!(line.starts_with("fuzzed.toml") && !line.contains('\n'), "{}", line);
            }
        }
    }
}
