//! Terrain benchmark: the cost of one foot contact (closest point, then the force of Eq.
//! 3.72-3.73) on a 100k-triangle mesh, against the flat ground in the same run (the baseline)
//! and the analytic step; the build of that mesh and the read of the shipped rough ground PLY.

use std::hint::black_box;
use std::path::Path;
use std::time::Instant;

use hexadyn::physics::terrain::ply;
use hexadyn::physics::{FlatGround, GroundContact, Heightfield, Step, Terrain};
use nalgebra::Vector3;
use rand::{Rng, SeedableRng};
use rand_chacha::ChaCha8Rng;

const QUERIES: usize = 100_000;

/// Median ns per contact force over `rounds` passes over the queries.
fn time_contact(terrain: &dyn Terrain, contact: &GroundContact, queries: &[(Vector3<f64>, Vector3<f64>)]) -> f64 {
    let mut per_round = Vec::new();
    for _ in 0..7 {
        let start = Instant::now();
        for (p, v) in queries {
            black_box(contact.force(black_box(p), black_box(v), terrain));
        }
        per_round.push(start.elapsed().as_nanos() as f64 / queries.len() as f64);
    }
    per_round.sort_by(f64::total_cmp);
    per_round[per_round.len() / 2]
}

fn main() {
    // A rolling heightfield of 224 x 224 cells: 100,352 triangles over 11.2 m x 11.2 m.
    let (n, spacing) = (225, 0.05);
    let heights: Vec<Vec<f64>> = (0..n)
        .map(|j| (0..n).map(|i| {
            let (x, y) = (i as f64 * spacing, j as f64 * spacing);
            0.03 * (1.3 * x).sin() * (0.9 * y).cos() + 0.01 * (7.0 * x + 3.0 * y).sin()
        }).collect())
        .collect();
    let start = Instant::now();
    let field = Heightfield::new([0.0, 0.0], spacing, heights).expect("finite heights");
    let build = start.elapsed().as_secs_f64();
    let triangles = field.triangles(hexadyn::physics::Extent { centre: [0.0; 2], half_width: 0.0 }).faces.len();

    // Feet within 5 mm of the ground, slipping slowly: the queries of a walk.
    let mut rng = ChaCha8Rng::seed_from_u64(1);
    let queries: Vec<(Vector3<f64>, Vector3<f64>)> = (0..QUERIES)
        .map(|_| {
            let (x, y) = (rng.random_range(0.5..10.7), rng.random_range(0.5..10.7));
            let z = field.height_normal(x, y).0 + rng.random_range(-5e-3..5e-3);
            (Vector3::new(x, y, z), Vector3::new(rng.random_range(-0.01..0.01), 0.0, rng.random_range(-0.01..0.01)))
        })
        .collect();
    let contact = GroundContact { k_gnd: 1e6, d_gnd: 5e4, p_k: 1.5, p_d: 0.5, mu: 0.7, v_glim: 1e-4, foot_radius: 0.0 };
    let flat = time_contact(&FlatGround { height: 0.0 }, &contact, &queries);
    let step = time_contact(&Step { base: 0.0, rise: 0.08, edge: 5.0, azimuth: 0.3 }, &contact, &queries);
    let mesh = time_contact(&field, &contact, &queries);
    let sphere = time_contact(&field, &GroundContact { foot_radius: 0.02, ..contact }, &queries);

    println!("hexadyn terrain benchmark ({QUERIES} foot contacts, median of 7 passes)");
    println!("  flat ground (baseline)                  {flat:>8.1} ns per contact");
    println!("  analytic step                           {step:>8.1} ns per contact = {:>6.1} x flat", step / flat);
    println!("  mesh, {triangles} triangles, point foot  {mesh:>8.1} ns per contact = {:>6.1} x flat", mesh / flat);
    println!("  mesh, {triangles} triangles, r = 2 cm    {sphere:>8.1} ns per contact = {:>6.1} x flat", sphere / flat);
    println!("  building that mesh (BVH, pseudo-normals) {:>8.1} ms", build * 1e3);

    let path = Path::new(env!("CARGO_MANIFEST_DIR")).join("../python/hexadyn/scenarios/terrains/rough_ground.ply");
    let start = Instant::now();
    match ply::read_terrain(&path) {
        Ok(t) => println!("  reading rough_ground.ply ({} triangles)  {:>8.1} ms", t.triangle_count(), start.elapsed().as_secs_f64() * 1e3),
        Err(e) => println!("  reading rough_ground.ply: {e}"),
    }
}
