//! Terrain benchmark: the cost of one foot contact (closest point, then the force of Eq.
//! 3.72-3.73) on a 100k-triangle mesh, against the flat ground in the same run (the baseline)
//! and the analytic step; the build of that mesh and the read of the shipped rough ground PLY;
//! the memory of reading a 2-million-triangle PLY terrain (the peak resident memory of the read
//! and of the mesh it keeps, Linux's VmHWM reset through /proc/self/clear_refs) against the
//! file's vertex and face data and against parry3d's oriented `TriMesh` of the same triangles
//! (the structure hexadyn used before, built in the same run).

use std::hint::black_box;
use std::path::Path;
use std::time::Instant;

use hexadyn::physics::terrain::ply::{self, PlyFormat};
use hexadyn::physics::{Extent, FlatGround, GroundContact, Heightfield, Step, Terrain, Triangles};
use parry3d_f64::math::Vector as PVec;
use parry3d_f64::shape::{TriMesh, TriMeshFlags};
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
    let args: Vec<String> = std::env::args().collect();
    if let [_, flag, which, path] = &args[..] {
        if flag == "--memory" {
            return memory_child(which, Path::new(path));
        }
    }
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
    println!("  building that mesh (grid of faces)       {:>8.1} ms", build * 1e3);

    let path = Path::new(env!("CARGO_MANIFEST_DIR")).join("../python/hexadyn/scenarios/terrains/rough_ground.ply");
    let start = Instant::now();
    match ply::read_terrain(&path) {
        Ok(t) => println!("  reading rough_ground.ply ({} triangles)  {:>8.1} ms", t.triangle_count(), start.elapsed().as_secs_f64() * 1e3),
        Err(e) => println!("  reading rough_ground.ply: {e}"),
    }

    memory();
}

/// A field of /proc/self/status in bytes (its value is in kB).
fn status_bytes(field: &str) -> f64 {
    let status = std::fs::read_to_string("/proc/self/status").unwrap_or_default();
    let kb = status.lines().find(|l| l.starts_with(field)).and_then(|l| l.split_whitespace().nth(1)?.parse::<f64>().ok());
    kb.map_or(f64::NAN, |kb| kb * 1024.0)
}

/// The child process of [`memory`]: reads the PLY at `path` as hexadyn's terrain or, for
/// `parry`, builds parry3d's oriented `TriMesh` of its triangles; prints the peak and the kept
/// resident memory (bytes) over the memory before, Linux's VmHWM reset through
/// /proc/self/clear_refs.
fn memory_child(which: &str, path: &Path) {
    let base = status_bytes("VmRSS:");
    let mesh = ply::read_terrain(path).expect("the bench's PLY");
    if which != "parry" {
        println!("{} {}", status_bytes("VmHWM:") - base, status_bytes("VmRSS:") - base);
        return;
    }
    // From the triangles in memory: the read of the file (the same as hexadyn's) not counted.
    let t = mesh.triangles(Extent { centre: [0.0; 2], half_width: 0.0 });
    drop(mesh);
    std::fs::write("/proc/self/clear_refs", "5").expect("Linux's clear_refs");
    let base = status_bytes("VmRSS:") - (24 * t.vertices.len() + 12 * t.faces.len()) as f64;
    let Triangles { vertices, faces } = t;
    let points = vertices.iter().map(|p| PVec::new(p[0], p[1], p[2])).collect();
    drop(vertices);
    let oracle = TriMesh::with_flags(points, faces, TriMeshFlags::ORIENTED | TriMeshFlags::MERGE_DUPLICATE_VERTICES).expect("a valid mesh");
    println!("{} {}", status_bytes("VmHWM:") - base, status_bytes("VmRSS:") - base);
    drop(oracle);
}

/// The memory of a 1000 x 1000 vertex grid (1 996 002 triangles) read from a binary PLY, each
/// reader in a child process of its own (the allocator's large blocks returned to the system at
/// once: glibc's fixed mmap threshold).
fn memory() {
    let n = 1000;
    let heights: Vec<Vec<f64>> = (0..n).map(|j| (0..n).map(|i| 0.02 * ((i * 7 + j * 13) % 17) as f64 / 17.0).collect()).collect();
    let grid: Triangles = Heightfield::new([0.0, 0.0], 0.01, heights).expect("finite heights").triangles(Extent { centre: [0.0; 2], half_width: 0.0 });
    let (vertices, triangles) = (grid.vertices.len(), grid.faces.len());
    let path = std::env::temp_dir().join(format!("hexadyn-terrain-bench-{}.ply", std::process::id()));
    let mut out = std::io::BufWriter::new(std::fs::File::create(&path).expect("temporary file"));
    ply::write(&grid, PlyFormat { encoding: ply::Encoding::BinaryLittleEndian, double: false }, &mut out).expect("PLY written");
    drop(out);
    // The vertex and face data of the file: 3 floats a vertex, a count byte and 3 ints a face.
    let data = (12 * vertices + 13 * triangles) as f64;
    let measure = |which: &str| -> Option<(f64, f64)> {
        let out = std::process::Command::new(std::env::current_exe().ok()?).args(["--memory", which]).arg(&path).env("GLIBC_TUNABLES", "glibc.malloc.mmap_threshold=131072").output().ok()?;
        let text = String::from_utf8_lossy(&out.stdout);
        let mut values = text.split_whitespace().map(|v| v.parse::<f64>().ok());
        Some((values.next()??, values.next()??))
    };
    let (ours, parry) = (measure("hexadyn"), measure("parry"));
    let _ = std::fs::remove_file(&path);
    let (Some((peak, held)), Some((parry_peak, parry_held))) = (ours, parry) else {
        println!("  memory: not measured (Linux's /proc/self/status and clear_refs needed)");
        return;
    };
    let per = |bytes: f64| bytes / triangles as f64;
    println!("  memory, a {triangles}-triangle binary PLY ({:.1} MB of vertex and face data, {:.1} B a triangle):", data / 1e6, per(data));
    println!("    hexadyn read_terrain   peak {:>6.1} B/triangle = {:>4.1} x the data, kept {:>6.1} B/triangle", per(peak), peak / data, per(held));
    println!("    parry3d TriMesh (was)  peak {:>6.1} B/triangle = {:>4.1} x the data, kept {:>6.1} B/triangle (the file's read not counted)", per(parry_peak), parry_peak / data, per(parry_held));
    println!("    hexadyn / parry3d peak {:>6.2}", peak / parry_peak);
}
