//! Issue 39: a PLY terrain loads within a few times its file's vertex and face data. The only
//! test of its binary, so that the process's peak resident memory (Linux's VmHWM) is the load's:
//! the file is written as a stream (no mesh in memory before the load).
#![cfg(target_os = "linux")]

use std::io::Write;

use hexadyn::physics::terrain::ply;

/// A field of /proc/self/status in bytes.
fn status_bytes(field: &str) -> f64 {
    let status = std::fs::read_to_string("/proc/self/status").expect("Linux's /proc/self/status");
    let line = status.lines().find(|l| l.starts_with(field)).unwrap_or_else(|| panic!("{field} in /proc/self/status"));
    line.split_whitespace().nth(1).and_then(|kb| kb.parse::<f64>().ok()).expect("a size in kB") * 1024.0
}

/// A binary PLY of an n x n vertex grid (2 (n - 1)² triangles) of rolling heights, streamed.
fn write_grid(path: &std::path::Path, n: u32) -> (usize, usize) {
    let mut out = std::io::BufWriter::new(std::fs::File::create(path).expect("temporary file"));
    let faces = 2 * (n - 1) * (n - 1);
    write!(out, "ply\nformat binary_little_endian 1.0\nelement vertex {}\nproperty float x\nproperty float y\nproperty float z\nelement face {faces}\nproperty list uchar int vertex_indices\nend_header\n", n * n).unwrap();
    for j in 0..n {
        for i in 0..n {
            let z = 0.02 * (0.3 * i as f32).sin() * (0.2 * j as f32).cos();
            for v in [0.01 * i as f32, 0.01 * j as f32, z] {
                out.write_all(&v.to_le_bytes()).unwrap();
            }
        }
    }
    for j in 0..n - 1 {
        for i in 0..n - 1 {
            let k = j * n + i;
            for face in [[k, k + 1, k + n + 1], [k, k + n + 1, k + n]] {
                out.write_all(&[3]).unwrap();
                face.iter().for_each(|v| out.write_all(&v.to_le_bytes()).unwrap());
            }
        }
    }
    out.flush().unwrap();
    ((n * n) as usize, faces as usize)
}

/// 1.1 million triangles: the load's peak over the memory before it is at most 4 times the
/// file's 12 bytes a vertex and 13 a face (measured 2.9 times on 2 million,
/// `benches/src/bin/terrain.rs`; parry3d's oriented `TriMesh` took 24 times).
#[test]
fn a_ply_terrain_loads_within_four_times_its_data() {
    let path = std::env::temp_dir().join(format!("hexadyn-ply-memory-{}.ply", std::process::id()));
    let (vertices, faces) = write_grid(&path, 750);
    let before = status_bytes("VmRSS:");
    let mesh = ply::read_terrain(&path);
    let peak = status_bytes("VmHWM:") - before;
    std::fs::remove_file(&path).unwrap();
    assert_eq!(mesh.expect("a valid PLY").triangle_count(), faces);
    let data = (12 * vertices + 13 * faces) as f64;
    assert!(peak < 4.0 * data, "peak {:.1} MB, {:.2} x the file's {:.1} MB of vertex and face data", peak / 1e6, peak / data, data / 1e6);
}
