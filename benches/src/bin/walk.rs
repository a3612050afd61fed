//! Walking benchmark, end to end through the shipped scenarios (settling, gait controller,
//! recording): the thesis' simulation-time case (Section 3.4.1: tripod, T = 15 s, V_x = 2 cm/s,
//! 75 s, LuGre, 42-DOF model) and the Monte Carlo workload, the validation walk of Table 6.2
//! (tripod, T = 12 s, V_x = 1.5 cm/s, 60 s) with dry/viscous friction (Eq. 6.1), with and without
//! the load dependence of Eq. 5.12. Each is quoted as wall time, real-time factor and integration
//! work, against the baseline measured in the same run: the thesis' own figure, 75 s of walking
//! in 260 s (Table 3.2), scaled to the simulated duration. The physics figures (energy balance,
//! tracking and walking errors) are printed alongside so that a speed-up that changes them shows.
//! The last two cases repeat the first two with the thesis' Newton iteration on f alone
//! (`surrogate_iterations = 0`; the robot's default is 8), the baseline of the surrogate.
//! `walk [case]` runs only the case of that index (0 to 4), e.g. under a profiler.

use std::path::Path;

use hexadyn::scenario::{run_scenario, Scenario};

const THESIS_WALL_S: f64 = 260.0;
const THESIS_SIMULATED_S: f64 = 75.0;

fn scenario(file: &str, friction: &str, load_dependence: bool, surrogate_iterations: Option<usize>) -> Scenario {
    let path = Path::new(env!("CARGO_MANIFEST_DIR")).join("../python/hexadyn/scenarios").join(file);
    let text = std::fs::read_to_string(&path).expect("shipped scenario");
    let model = format!("[model]\nfriction = \"{friction}\"\nload_dependence = {load_dependence}\n");
    let integrator = surrogate_iterations.map_or(String::new(), |n| format!("\n[integrator]\nsurrogate_iterations = {n}\n"));
    let text = text.replace("[model]\nfriction = \"lugre\"\n", &model) + &integrator;
    Scenario::from_str(&text, &path.display().to_string(), path.parent().expect("scenario folder")).expect("valid scenario")
}

fn main() {
    let cases = [
        ("Section 3.4.1: T = 15 s, 2 cm/s, 75 s", scenario("simulation_time.toml", "lugre", false, None)),
        ("Table 6.2 1.5 cm/s, 60 s, dry/viscous", scenario("validation_tripod_1_5cm.toml", "dry_viscous", false, None)),
        ("  same, load-dependent (Eq. 5.12)", scenario("validation_tripod_1_5cm.toml", "dry_viscous", true, None)),
        ("3.4.1 LuGre, Newton on f alone", scenario("simulation_time.toml", "lugre", false, Some(0))),
        ("6.2 dry/viscous, Newton on f alone", scenario("validation_tripod_1_5cm.toml", "dry_viscous", false, Some(0))),
    ];
    println!("hexadyn walk benchmark: tripod walks end to end (settling, gait controller, recording), single core");
    println!(
        "{:<38} {:>7} {:>6} {:>9} {:>6} {:>5} {:>7} {:>7} {:>7} {:>5} {:>5} {:>9} {:>8} {:>8} {:>9}",
        "case", "wall s", "RTF", "vs thesis", "steps", "rej.", "Newton", "f eval.", "surr.", "Jac.", "LU", "energy %", "q_r mrad", "q_v mm", "XY err mm"
    );
    let only: Option<usize> = std::env::args().nth(1).map(|a| a.parse().unwrap());
    for (i, (name, s)) in cases.iter().enumerate() {
        if only.is_some_and(|o| o != i) { continue; }
        let r = run_scenario(s, |_| {}).expect("simulation");
        let m = &r.summary;
        let wall = m.wall_time_s;
        let thesis = THESIS_WALL_S * m.duration_s / THESIS_SIMULATED_S;
        let tracking = m.max_tracking_error.unwrap_or([f64::NAN; 3]);
        let xy = m.gait.as_ref().map_or(f64::NAN, |g| g.tracking_error_xy_max_m);
        println!(
            "{:<38} {:>7.3} {:>6.0} {:>8.0}x {:>6} {:>5} {:>7} {:>7} {:>7} {:>5} {:>5} {:>9.4} {:>8.3} {:>8.4} {:>9.3}",
            name,
            wall,
            m.duration_s / wall,
            thesis / wall,
            m.integration_steps,
            m.rejected_steps,
            m.newton_iterations,
            m.residual_evaluations,
            m.surrogate_evaluations,
            m.jacobian_evaluations,
            m.factorizations,
            100.0 * m.energy_balance_error_relative,
            tracking[0] * 1e3,
            tracking[1] * 1e3,
            xy * 1e3
        );
    }
}
