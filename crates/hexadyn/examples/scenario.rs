//! Runs a scenario file and prints its summary (the engine alone, without Python):
//! `cargo run --release -p hexadyn --example scenario -- python/hexadyn/scenarios/stand_six_legs.toml`

use hexadyn::scenario::{run_scenario, Scenario, SummaryValue};

fn main() {
    let Some(path) = std::env::args().nth(1) else {
        eprintln!("usage: scenario <file.toml> [column ...]");
        std::process::exit(2);
    };
    let scenario = Scenario::from_file(&path).unwrap_or_else(|e| {
        eprintln!("Error: {e}");
        std::process::exit(1);
    });
    let results = run_scenario(&scenario, |_| {}).unwrap_or_else(|e| {
        eprintln!("Error: {e}");
        std::process::exit(1);
    });
    for (name, value) in results.summary.entries() {
        match value {
            SummaryValue::Text(s) => println!("{name:<32} {s}"),
            SummaryValue::Count(n) => println!("{name:<32} {n}"),
            SummaryValue::Number(x) => println!("{name:<32} {x:.6e}"),
            SummaryValue::Flag(b) => println!("{name:<32} {b}"),
        }
    }
    // Optional columns: printed every 10 % of the run.
    let columns: Vec<String> = std::env::args().skip(2).collect();
    if !columns.is_empty() {
        let series = &results.series;
        let rows = series.len();
        let header: Vec<String> = std::iter::once("t".to_string()).chain(columns.iter().map(|c| format!("{c} [{}]", series.unit(c).unwrap_or("?")))).collect();
        println!("{}", header.join("\t"));
        let step = (rows / 10).max(1);
        for r in (0..rows).step_by(step).chain(((rows - 1) % step != 0).then_some(rows - 1)) {
            let mut line = vec![format!("{:.3}", series.values("t").unwrap()[r])];
            for c in &columns {
                line.push(series.values(c).map_or("-".to_string(), |v| format!("{:.6e}", v[r])));
            }
            println!("{}", line.join("\t"));
        }
    }
}
