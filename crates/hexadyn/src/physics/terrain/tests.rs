//! Terrain geometry against independent oracles: a brute-force closest point over all
//! triangles, the analytic step and heightfield against their meshes, planes tiled by triangles
//! against the analytic planes.

use nalgebra::Vector3;
use rand::Rng;

use super::*;
use crate::physics::GroundContact;
use crate::test_util::rng;

/// Closest point of triangle (a, b, c) to p (Ericson, Real-Time Collision Detection 5.1.5),
/// and whether it is inside the face (not on an edge or a vertex).
fn closest_on_triangle(p: Vector3<f64>, a: Vector3<f64>, b: Vector3<f64>, c: Vector3<f64>) -> (Vector3<f64>, bool) {
    let (ab, ac, ap) = (b - a, c - a, p - a);
    let (d1, d2) = (ab.dot(&ap), ac.dot(&ap));
    if d1 <= 0.0 && d2 <= 0.0 {
        return (a, false);
    }
    let bp = p - b;
    let (d3, d4) = (ab.dot(&bp), ac.dot(&bp));
    if d3 >= 0.0 && d4 <= d3 {
        return (b, false);
    }
    let vc = d1 * d4 - d3 * d2;
    if vc <= 0.0 && d1 >= 0.0 && d3 <= 0.0 {
        return (a + d1 / (d1 - d3) * ab, false);
    }
    let cp = p - c;
    let (d5, d6) = (ab.dot(&cp), ac.dot(&cp));
    if d6 >= 0.0 && d5 <= d6 {
        return (c, false);
    }
    let vb = d5 * d2 - d1 * d6;
    if vb <= 0.0 && d2 >= 0.0 && d6 <= 0.0 {
        return (a + d2 / (d2 - d6) * ac, false);
    }
    let va = d3 * d6 - d5 * d4;
    if va <= 0.0 && (d4 - d3) >= 0.0 && (d5 - d6) >= 0.0 {
        return (b + (d4 - d3) / ((d4 - d3) + (d5 - d6)) * (c - b), false);
    }
    let denom = 1.0 / (va + vb + vc);
    (a + ab * (vb * denom) + ac * (vc * denom), true)
}

/// Brute force over all triangles of a ground that every vertical line crosses once (a height
/// field, possibly with vertical faces): the closest point gives the distance, the side comes
/// from the height of the surface above or below p on its vertical line; inside, the normal is
/// the blend of every triangle's normal (turned up as the mesh turns them) by its distance.
fn brute_force(t: &Triangles, p: Vector3<f64>, radius: f64) -> Proximity {
    let v = |i: u32| Vector3::from(t.vertices[i as usize]);
    let mut best = (f64::INFINITY, Vector3::zeros(), Vector3::zeros(), false);
    let mut surface_z = f64::NEG_INFINITY;
    let mut faces = Vec::new();
    for f in &t.faces {
        let (a, b, c) = (v(f[0]), v(f[1]), v(f[2]));
        let (s, on_face) = closest_on_triangle(p, a, b, c);
        let n = (b - a).cross(&(c - a));
        let d = (p - s).norm();
        faces.push((if n.z < 0.0 { -n } else { n }.normalize(), d, (p - s) / d));
        if d < best.0 {
            best = (d, s, n.normalize(), on_face);
        }
        // Height of the triangle on p's vertical line (barycentric in the xy projection).
        if n.z.abs() > 1e-12 {
            let w = |q: Vector3<f64>, r: Vector3<f64>| (r.x - q.x) * (p.y - q.y) - (r.y - q.y) * (p.x - q.x);
            let (wa, wb, wc) = (w(b, c), w(c, a), w(a, b));
            if (wa >= 0.0 && wb >= 0.0 && wc >= 0.0) || (wa <= 0.0 && wb <= 0.0 && wc <= 0.0) {
                surface_z = surface_z.max(a.z - (n.x * (p.x - a.x) + n.y * (p.y - a.y)) / n.z);
            }
        }
    }
    let (d, s, face_normal, on_face) = best;
    let sign = if p.z < surface_z { -1.0 } else { 1.0 };
    let closest = if on_face { face_normal * face_normal.dot(&(p - s)).signum() * sign } else { sign * (p - s) / d };
    let normal = if sign < 0.0 {
        let mut blend = InsideNormal::new(d, closest, nalgebra::Matrix3::zeros());
        faces.into_iter().enumerate().for_each(|(key, (n, e, gradient))| blend.add(key as u32, n, e, gradient));
        blend.normal().0
    } else {
        closest
    };
    // Only the penetration and the normal are compared.
    Proximity {
        penetration: radius - sign * d,
        normal,
        penetration_gradient: -closest,
        penetration_hessian: nalgebra::Matrix3::zeros(),
        normal_jacobian: nalgebra::Matrix3::zeros(),
    }
}

fn random_heightfield(seed: u64, n: usize, spacing: f64) -> Heightfield {
    let mut r = rng(seed);
    let heights = (0..n).map(|_| (0..n).map(|_| r.random_range(-0.05..0.05)).collect()).collect();
    Heightfield::new([0.0, 0.0], spacing, heights).unwrap()
}

/// Random points over the middle of a square [0, w]², within `band` of the surface height.
fn random_query(r: &mut impl Rng, terrain: &dyn Terrain, w: f64, band: f64) -> Vector3<f64> {
    let (x, y) = (r.random_range(0.1 * w..0.9 * w), r.random_range(0.1 * w..0.9 * w));
    Vector3::new(x, y, terrain.height_normal(x, y).0 + r.random_range(-band..band))
}

#[test]
fn mesh_proximity_matches_brute_force_on_ten_thousand_queries() {
    // A random heightfield (1682 triangles) and a block with vertical faces.
    let field = random_heightfield(31, 30, 0.1);
    let block = generate::step_block(0.08);
    let block_mesh = MeshTerrain::new(block.clone()).unwrap();
    let field_triangles = field.triangles(Extent { centre: [0.0; 2], half_width: 0.0 });
    let mut r = rng(32);
    for k in 0..10_000 {
        let radius = if k % 2 == 0 { 0.0 } else { 0.02 };
        let (terrain, triangles, p): (&dyn Terrain, &Triangles, Vector3<f64>) = if k % 4 < 2 {
            (&field, &field_triangles, random_query(&mut r, &field, 2.9, 0.08))
        } else {
            let p = Vector3::new(r.random_range(0.7..3.3), r.random_range(-0.4..0.2), r.random_range(-0.05..0.13));
            (&block_mesh, &block, p)
        };
        let got = terrain.proximity(&p, radius);
        let want = brute_force(triangles, p, radius);
        assert!((got.penetration - want.penetration).abs() < 1e-9, "query {k} at {p:?}: δ = {} vs brute force {}", got.penetration, want.penetration);
        assert!((got.normal - want.normal).norm() < 1e-9, "query {k} at {p:?}: n = {:?} vs brute force {:?}", got.normal, want.normal);
    }
}

#[test]
fn a_foot_vicinity_gives_the_whole_mesh_answer() {
    // Feet wandering over a random heightfield and around a block with vertical faces, in
    // steps from a micrometre (a foot on the ground) to 5 cm (a swing, a reset), each keeping
    // its vicinity: the contact must be that of the search over the whole mesh, bit for bit.
    let field = random_heightfield(33, 30, 0.1);
    let block = MeshTerrain::new(generate::step_block(0.08)).unwrap();
    let mut r = rng(34);
    let mut gathered = 0;
    for (terrain, y_range) in [(&field as &dyn Terrain, 0.8f64..2.2), (&block, -0.4..0.2)] {
        let mut vicinity = Vicinity::default();
        let mut p = Vector3::<f64>::new(1.5, y_range.start, 0.0);
        for k in 0..20_000 {
            let step = [1e-6, 1e-6, 1e-4, 3e-3, 5e-2][r.random_range(0..5)];
            p += step * Vector3::new(r.random_range(-1.0..1.0), r.random_range(-1.0..1.0), r.random_range(-1.0..1.0));
            // Kept over the middle of the terrain, from 1 cm below its surface to 8 cm above.
            p.x = p.x.clamp(0.8, 2.2);
            p.y = p.y.clamp(y_range.start, y_range.end);
            let h = terrain.height_normal(p.x, p.y).0;
            p.z = p.z.clamp(h - 0.01, h + 0.08);
            let radius = if k % 3 == 0 { 0.02 } else { 0.0 };
            let before = vicinity.reach;
            let got = terrain.proximity_near(&p, radius, &mut vicinity);
            gathered += usize::from(vicinity.reach != before);
            let want = terrain.proximity(&p, radius);
            assert_eq!(got, want, "query {k} at {p:?}");
            if k % 1000 == 999 {
                // A trial state far from the ground (a Newton iterate gone astray): the answer of
                // the whole mesh, and no vicinity kept that would hold most of the mesh.
                let far = p + Vector3::new(0.0, 0.0, 1.0);
                assert_eq!(terrain.proximity_near(&far, radius, &mut vicinity), terrain.proximity(&far, radius));
                assert_eq!(vicinity.reach, 0.0);
            }
        }
    }
    // Both the vicinity and the whole-mesh search answered (the test exercises both paths).
    assert!(gathered > 100 && gathered < 30_000, "{gathered} of 40 000 queries gathered a new vicinity");
}

#[test]
fn sliding_across_a_tiled_plane_feels_no_edge() {
    // The plane z = 0.1 + 0.2 x - 0.1 y tiled by 2 x 22 x 22 = 968 triangles.
    let slope = Slope { height: 0.1, slope_x: 0.2, slope_y: -0.1 };
    let n = 23;
    let heights = (0..n).map(|j| (0..n).map(|i| slope.height_normal(i as f64 * 0.05, j as f64 * 0.05).0).collect()).collect();
    let tiled = Heightfield::new([0.0, 0.0], 0.05, heights).unwrap();
    assert_eq!(tiled.triangles(Extent { centre: [0.0; 2], half_width: 0.0 }).faces.len(), 968);
    for radius in [0.0, 0.02] {
        let contact = GroundContact { foot_radius: radius, ..GroundContact::default() };
        let (_, normal) = slope.height_normal(0.0, 0.0);
        let depth = 1e-3;
        // A straight slide over the plane at constant depth, crossing edges, diagonals and vertices.
        let (start, end) = (Vector3::new(0.2, 0.13, 0.0), Vector3::new(0.93, 0.87, 0.0));
        let v = Vector3::new(0.01, 0.003, 0.0);
        let reference = contact.force(&(Vector3::new(0.5, 0.5, slope.height_normal(0.5, 0.5).0) - (depth - radius) * normal), &v, &slope);
        for k in 0..=2000 {
            let q = start + (end - start) * (k as f64 / 2000.0);
            let p = Vector3::new(q.x, q.y, slope.height_normal(q.x, q.y).0) - (depth - radius) * normal;
            let on_mesh = contact.force(&p, &v, &tiled);
            let analytic = contact.force(&p, &v, &slope);
            assert!((on_mesh.normal_force / reference.normal_force - 1.0).abs() < 1e-6, "r = {radius}, sample {k}: F_n = {} vs {}", on_mesh.normal_force, reference.normal_force);
            assert!((on_mesh.force - analytic.force).norm() < 1e-6 * analytic.force.norm(), "r = {radius}, sample {k}: {:?} vs {:?}", on_mesh.force, analytic.force);
        }
    }
}

#[test]
fn flat_ground_mesh_gives_the_flat_ground_force() {
    let flat = FlatGround { height: 0.02 };
    let mesh = MeshTerrain::new(flat.triangles(Extent { centre: [0.0, 0.0], half_width: 2.0 })).unwrap();
    let contact = GroundContact::default();
    let mut r = rng(33);
    for _ in 0..1000 {
        let p = Vector3::new(r.random_range(-1.5..1.5), r.random_range(-1.5..1.5), 0.02 - r.random_range(-1e-3..5e-3));
        let v = Vector3::new(r.random_range(-0.01..0.01), r.random_range(-0.01..0.01), r.random_range(-0.01..0.01));
        let (a, b) = (contact.force(&p, &v, &flat), contact.force(&p, &v, &mesh));
        assert!((a.force - b.force).norm() <= 1e-9 * (1.0 + a.force.norm()), "{a:?} vs {b:?}");
        assert!((a.penetration - b.penetration).abs() < 1e-12);
    }
}

#[test]
fn analytic_step_matches_its_mesh() {
    let mut r = rng(34);
    for _ in 0..20 {
        let step = Step { base: r.random_range(-0.1..0.1), rise: r.random_range(0.01..0.12), edge: r.random_range(-0.5..0.5), azimuth: r.random_range(-3.0..3.0) };
        let mesh = MeshTerrain::new(step.triangles(Extent { centre: [0.1, -0.2], half_width: 2.0 })).unwrap();
        for _ in 0..500 {
            let u = Vector3::new(step.azimuth.cos(), step.azimuth.sin(), 0.0);
            // Points near the edge, well inside the meshed square.
            let p = u * (step.edge + r.random_range(-0.2..0.2)) + Vector3::new(-u.y, u.x, 0.0) * r.random_range(-1.0..1.0) + Vector3::new(0.0, 0.0, step.base + r.random_range(-0.05..step.rise + 0.05));
            let radius = r.random_range(0.0..0.03);
            let (a, b) = (step.proximity(&p, radius), mesh.proximity(&p, radius));
            assert!((a.penetration - b.penetration).abs() < 1e-9, "{step:?} at {p:?}: δ = {} vs mesh {}", a.penetration, b.penetration);
            assert!((a.normal - b.normal).norm() < 1e-9, "{step:?} at {p:?}: n = {:?} vs mesh {:?}", a.normal, b.normal);
            let (h, _) = step.height_normal(p.x, p.y);
            assert!((h - mesh.height_normal(p.x, p.y).0).abs() < 1e-9);
        }
    }
}

#[test]
fn step_edge_treatment() {
    let step = Step { base: 0.0, rise: 0.08, edge: 1.0, azimuth: 0.0 };
    // Above the top corner: pushed away from the corner, continuously.
    let p = step.proximity(&Vector3::new(0.99, 0.3, 0.09), 0.02);
    let d: Vector3<f64> = Vector3::new(-0.01, 0.0, 0.01);
    assert!((p.penetration - (0.02 - d.norm())).abs() < 1e-15);
    assert!((p.normal - d.normalize()).norm() < 1e-15);
    // A point foot sunk 5 mm into the top face: up while the face is twice as far as the top
    // (u = 1), along the bisector where both are as far, sideways once the top is twice as far.
    assert_eq!(step.proximity(&Vector3::new(1.01, 0.0, 0.075), 0.0).normal, Vector3::z());
    let bisector = step.proximity(&Vector3::new(1.005, 0.0, 0.075), 0.0);
    assert!((bisector.normal - Vector3::new(-1.0, 0.0, 1.0).normalize()).norm() < 1e-12 && (bisector.penetration - 0.005).abs() < 1e-15);
    // 4 mm from the face, 5 mm under the top: u = (5 - 4) / 4 = 1/4, φ = (3/4)² (3/2) = 27/32.
    let near_face = step.proximity(&Vector3::new(1.004, 0.0, 0.075), 0.0);
    assert!((near_face.normal - Vector3::new(-1.0, 0.0, 27.0 / 32.0).normalize()).norm() < 1e-12 && (near_face.penetration - 0.004).abs() < 1e-15);
    assert_eq!(step.proximity(&Vector3::new(1.0025, 0.0, 0.075), 0.0).normal, -Vector3::x());
    // In front of the face, low side.
    let p = step.proximity(&Vector3::new(0.97, 0.0, 0.04), 0.0);
    assert!((p.penetration + 0.03).abs() < 1e-15 && p.normal == -Vector3::x());
}

#[test]
fn heightfield_height_matches_its_mesh() {
    let field = random_heightfield(35, 12, 0.25);
    let mesh = MeshTerrain::new(field.triangles(Extent { centre: [0.0; 2], half_width: 0.0 })).unwrap();
    let mut r = rng(36);
    for _ in 0..5000 {
        let (x, y) = (r.random_range(0.0..2.75), r.random_range(0.0..2.75));
        let ((h, n), (hm, nm)) = (field.height_normal(x, y), mesh.height_normal(x, y));
        assert!((h - hm).abs() < 1e-9, "({x}, {y}): {h} vs mesh {hm}");
        assert!((n - nm).norm() < 1e-9, "({x}, {y}): {n:?} vs mesh {nm:?}");
    }
}

#[test]
fn mesh_faces_are_turned_up_and_bad_meshes_refused() {
    // A face given clockwise from above is turned over.
    let t = Triangles { vertices: vec![[0.0, 0.0, 0.0], [1.0, 0.0, 0.0], [0.0, 1.0, 0.0]], faces: vec![[0, 2, 1]] };
    let mesh = MeshTerrain::new(t.clone()).unwrap();
    assert!((mesh.proximity(&Vector3::new(0.2, 0.2, -0.01), 0.0).penetration - 0.01).abs() < 1e-15);
    let mut bad = t.clone();
    bad.vertices[1][2] = f64::NAN;
    assert!(matches!(MeshTerrain::new(bad), Err(MeshError::NonFiniteVertex { index: 1, .. })));
    let mut bad = t.clone();
    bad.faces[0] = [0, 1, 3];
    assert!(matches!(MeshTerrain::new(bad), Err(MeshError::IndexOutOfRange { face: 0, index: 3, .. })));
    let mut bad = t.clone();
    bad.vertices[2] = [2.0, 0.0, 0.0];
    assert!(matches!(MeshTerrain::new(bad), Err(MeshError::Degenerate { face: 0, .. })));
    assert_eq!(MeshTerrain::new(Triangles { vertices: t.vertices, faces: vec![] }).unwrap_err(), MeshError::Empty);
}

#[test]
fn shipped_terrains_are_the_generated_ones() {
    let folder = std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("../../python/hexadyn/scenarios/terrains");
    for (name, triangles) in generate::shipped() {
        let mut bytes = Vec::new();
        ply::write(&triangles, generate::SHIPPED_FORMAT, &mut bytes).unwrap();
        let path = folder.join(name);
        let shipped = std::fs::read(&path).unwrap_or_else(|e| panic!("{}: {e} (make terrains)", path.display()));
        assert!(shipped == bytes, "{} differs from what make_terrains generates (make terrains)", path.display());
        ply::parse_terrain(&shipped, name).unwrap();
    }
}

#[test]
fn shipped_terrains_have_the_geometry_of_section_7_7_5() {
    let step = MeshTerrain::new(generate::step_block(0.08)).unwrap();
    assert!((step.height_normal(2.0, -0.4).0 - 0.08).abs() < 1e-12);
    assert!(step.height_normal(2.0, 0.3).0.abs() < 1e-12);
    assert!(step.height_normal(0.5, -0.4).0.abs() < 1e-12);
    let ramp = MeshTerrain::new(generate::ramp(20f64.to_radians())).unwrap();
    let (_, n) = ramp.height_normal(1.0, 0.5);
    assert!((n.z.acos().to_degrees() - 20.0).abs() < 1e-4);
    let rough = generate::rough(0.015, 7);
    let z: Vec<f64> = rough.vertices.iter().filter(|v| v[0].hypot(v[1]) > 1.2).map(|v| v[2]).collect();
    let rms = (z.iter().map(|z| z * z).sum::<f64>() / z.len() as f64).sqrt();
    assert!((rms - 0.015).abs() < 0.003, "RMS {rms}");
    assert!(rough.vertices.iter().filter(|v| v[0].hypot(v[1]) < 0.6).all(|v| v[2] == 0.0));
    // The PhantomX's: a third of it, 5 mm RMS beyond 0.6 m, flat within 0.3 m, the field a
    // third of AMRU5's.
    let small = generate::PHANTOMX_ROUGH.triangles();
    let z: Vec<f64> = small.vertices.iter().filter(|v| v[0].hypot(v[1]) > 0.6).map(|v| v[2]).collect();
    let rms = (z.iter().map(|z| z * z).sum::<f64>() / z.len() as f64).sqrt();
    assert!((rms - 0.005).abs() < 0.001, "RMS {rms}");
    assert!(small.vertices.iter().filter(|v| v[0].hypot(v[1]) < 0.3).all(|v| v[2] == 0.0));
    let x_max = small.vertices.iter().map(|v| v[0]).fold(f64::NEG_INFINITY, f64::max);
    assert!((x_max - 14.0 / 3.0).abs() < 1e-9, "{x_max}");
}

/// A ridge of two faces, z = 0.1 - 0.2 |x| near x = 0 (slope angle θ/2 = atan 0.2 each side),
/// as a mesh of four triangles.
fn ridge() -> MeshTerrain {
    let z = |x: f64| 0.1 - 0.2 * x.abs();
    let vertices = vec![[-1.0, -1.0, z(-1.0)], [0.0, -1.0, z(0.0)], [1.0, -1.0, z(1.0)], [-1.0, 1.0, z(-1.0)], [0.0, 1.0, z(0.0)], [1.0, 1.0, z(1.0)]];
    MeshTerrain::new(Triangles { vertices, faces: vec![[0, 1, 4], [0, 4, 3], [1, 2, 5], [1, 5, 4]] }).unwrap()
}

#[test]
fn inside_normal_under_a_ridge_is_the_analytic_blend() {
    let ridge = ridge();
    let (n_left, n_right) = (Vector3::new(-0.2, 0.0, 1.0).normalize(), Vector3::new(0.2, 0.0, 1.0).normalize());
    // The analytic answer below the ridge line.
    let analytic = |p: Vector3<f64>| {
        // The plane's distance where the perpendicular's foot is on the face (x of the same
        // sign as the face's), else the distance to the ridge line.
        let distance = |n: Vector3<f64>, side: f64| {
            let d = n.dot(&(Vector3::new(0.0, 0.0, 0.1) - p));
            if (p + d * n).x * side >= 0.0 {
                d
            } else {
                (p.x * p.x + (0.1 - p.z).powi(2)).sqrt()
            }
        };
        let (d_left, d_right) = (distance(n_left, -1.0), distance(n_right, 1.0));
        let (e_min, e_other, n_near, n_far) = if d_left <= d_right { (d_left, d_right, n_left, n_right) } else { (d_right, d_left, n_right, n_left) };
        let u = ((e_other - e_min) / e_min).min(1.0);
        ((n_near + (1.0 - u).powi(2) * (1.0 + 2.0 * u) * n_far).normalize(), e_min)
    };
    for x in [-3e-4, -1e-4, -2e-5, 0.0, 1e-6, 5e-5, 2e-4, 6e-4] {
        let p = Vector3::new(x, 0.3, 0.1 - 1e-3);
        let (normal, depth) = analytic(p);
        let got = ridge.proximity(&p, 0.0);
        assert!((got.normal - normal).norm() < 1e-12, "x = {x}: {:?} vs {normal:?}", got.normal);
        assert!((got.penetration - depth).abs() < 1e-15, "x = {x}: δ = {} vs {depth}", got.penetration);
    }
    // Deep inside, the blend fades back to the closest face's normal: fully at 10 cm, halfway
    // (φ(1/2) = 1/2) at 7.5 cm.
    // A nanometre left of the bisector, the right face weighs φ(≈1e-8) = 1 in the blend.
    let deep = |depth: f64| ridge.proximity(&Vector3::new(-1e-9, 0.0, 0.1 - depth / n_left.z), 0.0).normal;
    assert!((deep(0.1) - n_left).norm() < 1e-15);
    let want = (0.5 * (n_left + n_right) + 0.5 * n_left).normalize();
    assert!((deep(0.075) - want).norm() < 1e-8, "{:?} vs {want:?}", deep(0.075));
    // On the bisector the mean of the two faces' normals; far from it, the face's own.
    assert!((ridge.proximity(&Vector3::new(0.0, 0.0, 0.099), 0.0).normal - Vector3::z()).norm() < 1e-15);
    assert!((ridge.proximity(&Vector3::new(0.01, 0.0, 0.097), 0.0).normal - n_right).norm() < 1e-15);
}

#[test]
fn a_point_foot_crossing_convex_edges_inside_the_ground_feels_a_continuous_normal() {
    // Point feet 1 mm inside a random rough heightfield (10 cm cells, ±5 cm: dihedral angles of
    // tens of degrees) slide along random lines in 0.1 µm steps: the normal may turn by at most
    // what a band of the penetration's width allows, never by an edge's dihedral angle.
    let field = random_heightfield(37, 12, 0.1);
    let mut r = rng(38);
    let mut turned = 0.0f64;
    for line in 0..60 {
        // From 1 mm before a grid line x = 0.2-0.8 or y = 0.2-0.8 (edges of the cells, convex or
        // concave at random) across it, at up to 60° from its normal.
        let grid = 0.1 * r.random_range(2..9) as f64 - 1e-3;
        let (x, y) = if line % 2 == 0 { (grid, r.random_range(0.2..0.8)) } else { (r.random_range(0.2..0.8), grid) };
        let direction = r.random_range(-1.0..1.0) + if line % 2 == 0 { 0.0 } else { std::f64::consts::FRAC_PI_2 };
        let along = Vector3::new(direction.cos(), direction.sin(), 0.0);
        let mut last: Option<Vector3<f64>> = None;
        for k in 0..20_000 {
            let q = Vector3::new(x, y, 0.0) + along * (k as f64 * 1e-7);
            let p = Vector3::new(q.x, q.y, field.height_normal(q.x, q.y).0 - 1e-3);
            let n = field.proximity(&p, 0.0).normal;
            if let Some(m) = last {
                turned = turned.max((n - m).norm());
            }
            last = Some(n);
        }
    }
    // Over a band of about 1 mm (1e4 steps) the normal turns by at most the dihedral angle (< 1 rad):
    // a step of 1e-7 m turns it by about 1e-4; a jump at the bisector would be 0.1-1.
    assert!(turned < 2e-3, "the normal turned by {turned} in one 0.1 µm step");
}
