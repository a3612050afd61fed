//! Seeded terrains: the grounds of the free-gait cases of Section 7.7.5 (an 8 cm step on the
//! right of the path, a 20° slope, rough ground), shipped as PLY files in
//! `python/hexadyn/scenarios/terrains/` by `make terrains`
//! (`cargo run --release -p hexadyn --example make_terrains`), and the terrain classes they
//! belong to (steps, ramps, rough ground of a given RMS height), for campaigns over seeds.
//!
//! Fig. 7.30, which showed the three terrains, is lost; the geometry below is read from the
//! text of Section 7.7.5 (INTERPRETATIONs at each function). The robot starts at the origin
//! heading along +x; its feet stand about 0.47 m ahead of and behind the body centre and
//! 0.27-0.54 m to its sides, so every terrain is flat within 0.6 m of the start.

use rand::{Rng, SeedableRng};
use rand_chacha::ChaCha8Rng;

use super::heightfield::grid_triangles;
use super::ply::PlyFormat;
use super::Triangles;
use ply_rs_bw::ply::Encoding;

/// A ground of horizontal rectangles on the grid `xs` × `ys` (increasing), cell (i, j) at
/// height `height(i, j)`, joined by vertical faces where neighbouring cells differ.
pub fn terraces(xs: &[f64], ys: &[f64], height: impl Fn(usize, usize) -> f64) -> Triangles {
    let mut t = Triangles::default();
    let mut quad = |corners: [[f64; 3]; 4]| {
        let first = t.vertices.len() as u32;
        t.vertices.extend(corners);
        t.faces.extend([[first, first + 1, first + 2], [first, first + 2, first + 3]]);
    };
    let (nx, ny) = (xs.len() - 1, ys.len() - 1);
    for i in 0..nx {
        for j in 0..ny {
            let z = height(i, j);
            let (x0, x1, y0, y1) = (xs[i], xs[i + 1], ys[j], ys[j + 1]);
            quad([[x0, y0, z], [x1, y0, z], [x1, y1, z], [x0, y1, z]]);
            // Faces towards the next cell in x and in y, facing the lower one.
            if i + 1 < nx {
                let zn = height(i + 1, j);
                if zn > z {
                    quad([[x1, y0, z], [x1, y0, zn], [x1, y1, zn], [x1, y1, z]]);
                } else if zn < z {
                    quad([[x1, y0, zn], [x1, y1, zn], [x1, y1, z], [x1, y0, z]]);
                }
            }
            if j + 1 < ny {
                let zn = height(i, j + 1);
                if zn > z {
                    quad([[x0, y1, z], [x1, y1, z], [x1, y1, zn], [x0, y1, zn]]);
                } else if zn < z {
                    quad([[x0, y1, zn], [x0, y1, z], [x1, y1, z], [x1, y1, zn]]);
                }
            }
        }
    }
    t
}

/// A ground z = f(x), piecewise linear through (`xs`, `zs`), over y in [y0, y1]; `xs` is
/// non-decreasing, and a repeated x makes a vertical face (a riser or a drop), facing the lower
/// side.
pub fn profile(xs: &[f64], zs: &[f64], (y0, y1): (f64, f64)) -> Triangles {
    let mut t = Triangles::default();
    for (&x, &z) in xs.iter().zip(zs) {
        t.vertices.extend([[x, y0, z], [x, y1, z]]);
    }
    for k in 0..xs.len() as u32 - 1 {
        let (a, b, c, d) = (2 * k, 2 * k + 2, 2 * k + 3, 2 * k + 1);
        t.faces.extend([[a, b, c], [a, c, d]]);
    }
    t
}

/// `t` turned by `azimuth` (rad) about the vertical axis through the origin.
pub fn rotated(mut t: Triangles, azimuth: f64) -> Triangles {
    let (sin, cos) = azimuth.sin_cos();
    for v in &mut t.vertices {
        *v = [cos * v[0] - sin * v[1], sin * v[0] + cos * v[1], v[2]];
    }
    t
}

/// A raised block of height `rise` under the right side of a straight path along +x: flat
/// ground over x in [-1.5, 5.5] m, y in [-1.5, 1.5] m, the block over x in [1, 3] m and
/// y < -0.1 m.
///
/// INTERPRETATION (Section 7.7.5, case 1: "a step as obstacle of 8 cm high on the right of the
/// robot", 400 s at 1 cm/s): the roll goes down while climbing, "stays constant during the
/// crossing" and returns to zero on flat ground, and the pitch is negative on the way up,
/// zero on the step and positive on the way down: only the right legs (1, 3, 5) climb, onto a
/// block they later leave. The block starts 1 m ahead (the feet start on flat ground), is 2 m
/// long (all three right feet stand on it for about 1 m of the path) and ends 1 m before the
/// end of the 4 m path (every foot is back on the ground at the end). Its inner edge at
/// y = -0.1 m keeps the left feet (y >= 0.27 m) off it.
pub fn step_block(rise: f64) -> Triangles {
    terraces(&[-1.5, 1.0, 3.0, 5.5], &[-1.5, -0.1, 1.5], |i, j| if i == 1 && j == 0 { rise } else { 0.0 })
}

/// A ramp of `angle` (rad) rising along +x from x = 0.5 m over 1.1 m of run, flat below and
/// above, over x in [-1.5, 3.5] m, y in [-1.5, 2.5] m.
///
/// INTERPRETATION (Section 7.7.5, case 2: a square of straight lines along X and Y, 100 s each
/// at 1 cm/s, so 1 m sides, on "a slope of 20 degrees"; "the pitch adapts to 20°" and "the
/// initial clearance is correctly retrieved after the climbing"): the robot starts on flat
/// ground with its front feet 3 cm before the ramp; after the first side (body at x = 1 m)
/// its six feet (x in [0.53, 1.47] m) stand on the ramp, where the second side runs along it;
/// the third side brings it back down. The ramp ends at x = 1.6 m, out of the square's reach,
/// with a flat top beyond. The square's sides run +x, +y, -x, -y (the ground extends 1.5 m
/// beyond the square on every side).
pub fn ramp(angle: f64) -> Triangles {
    let (start, run) = (0.5, 1.1);
    let top = run * angle.tan();
    profile(&[-1.5, start, start + run, 3.5], &[0.0, 0.0, top, top], (-1.5, 2.5))
}

/// Radius around the origin within which [`rough`] ground is flat (m).
pub const ROUGH_FLAT_RADIUS: f64 = 0.6;
/// Radius beyond which [`rough`] ground has its full roughness (m).
pub const ROUGH_FULL_RADIUS: f64 = 1.2;

/// Rough ground: heights on a 0.1 m grid over x in [-2, 14] m, y in [-6, 6] m, a sum of 64
/// cosine waves of random direction, wavelength in [0.3, 3] m and phase, drawn from `seed`,
/// scaled to the RMS height `rms` (m), faded to flat ground within 0.6 m of the origin (smooth
/// step from 0.6 to 1.2 m).
///
/// INTERPRETATION (Section 7.7.5, case 3: "a completely uneven ground" under a 1000 s spline at
/// most 2 cm/s, so at most 20 m long): a 16 m × 12 m field around the path; the wavelengths
/// range from half the foot spacing to several robot lengths, so the feet meet both bumps and
/// inclines.
pub fn rough(rms: f64, seed: u64) -> Triangles {
    RoughGround { rms, seed, length_scale: 1.0, flat_radius: ROUGH_FLAT_RADIUS, full_radius: ROUGH_FULL_RADIUS }.triangles()
}

/// The smooth step (3u² − 2u³) from 0 within `flat` (m) of the origin to 1 beyond `full`.
fn fade(r: f64, flat: f64, full: f64) -> f64 {
    let u = ((r - flat) / (full - flat)).clamp(0.0, 1.0);
    u * u * (3.0 - 2.0 * u)
}

/// The parameters of a [`rough`] ground for a robot of another size.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct RoughGround {
    /// RMS height (m).
    pub rms: f64,
    /// Seed of the waves' directions, wavelengths and phases.
    pub seed: u64,
    /// Factor on every horizontal length of [`rough`]: the grid spacing, the field and the
    /// wavelengths (1: AMRU5's ground).
    pub length_scale: f64,
    /// Radius around the origin within which the ground is flat, and beyond which it has its
    /// full roughness (m).
    pub flat_radius: f64,
    pub full_radius: f64,
}

impl RoughGround {
    /// The ground of [`rough`] with these parameters.
    pub fn triangles(&self) -> Triangles {
        let (rms, s) = (self.rms, self.length_scale);
        let mut rng = ChaCha8Rng::seed_from_u64(self.seed);
        let waves: Vec<(f64, f64, f64)> = (0..64)
            .map(|_| {
                let direction = rng.random_range(0.0..std::f64::consts::TAU);
                let wavelength = rng.random_range(0.3 * s..3.0 * s);
                let k = std::f64::consts::TAU / wavelength;
                (k * direction.cos(), k * direction.sin(), rng.random_range(0.0..std::f64::consts::TAU))
            })
            .collect();
        // Each unit cosine has mean square 1/2: the sum of 64 has RMS 4 (independent phases).
        let scale = rms / (waves.len() as f64 / 2.0).sqrt();
        let (spacing, origin, (nx, ny)) = (0.1 * s, [-2.0 * s, -6.0 * s], (161, 121));
        let heights: Vec<Vec<f64>> = (0..ny)
            .map(|j| {
                (0..nx)
                    .map(|i| {
                        let (x, y) = (origin[0] + i as f64 * spacing, origin[1] + j as f64 * spacing);
                        let z: f64 = waves.iter().map(|&(kx, ky, phase)| (kx * x + ky * y + phase).cos()).sum();
                        scale * z * fade(x.hypot(y), self.flat_radius, self.full_radius)
                    })
                    .collect()
            })
            .collect();
        grid_triangles(origin, spacing, &heights)
    }
}

/// A boulder field: spherical caps on flat ground, heights on a 2.5 cm grid over x in [-2, 6] m,
/// y in [-2.5, 2.5] m, scaled to the RMS height `rms` (m) where the field is full, faded to flat
/// ground as [`rough`] (flat within 0.6 m of the origin, full beyond 1.2 m).
///
/// INTERPRETATION (issue 37's boulder fields of RMS 1-3 cm; the thesis has none): 3 boulders per
/// square metre at uniform positions, base radius uniform in [5, 20] cm and height 0.3-0.7 times
/// it before the scaling, drawn from `seed`; the ground is the highest cap over each point. The
/// caps' steep flanks and the flat ground between them are what distinguishes them from the
/// smooth waves of [`rough`] ground.
pub fn boulders(rms: f64, seed: u64) -> Triangles {
    let mut rng = ChaCha8Rng::seed_from_u64(seed);
    let (spacing, origin, (nx, ny)) = (0.025, [-2.0, -2.5], (321, 201));
    let area = (nx - 1) as f64 * spacing * (ny - 1) as f64 * spacing;
    // (x, y, sphere radius, height of its centre): a cap of base radius b and height h lies on
    // the sphere of radius (b² + h²) / 2h centred h − ρ below the ground.
    let caps: Vec<[f64; 4]> = (0..(3.0 * area).round() as usize)
        .map(|_| {
            let (x, y) = (rng.random_range(origin[0]..origin[0] + 8.0), rng.random_range(origin[1]..origin[1] + 5.0));
            let b = rng.random_range(0.05..0.2);
            let h = b * rng.random_range(0.3..0.7);
            let rho = (b * b + h * h) / (2.0 * h);
            [x, y, rho, h - rho]
        })
        .collect();
    let cap_height = |x: f64, y: f64| caps.iter().map(|&[cx, cy, rho, zc]| (rho * rho - (x - cx).powi(2) - (y - cy).powi(2)).max(0.0).sqrt() + zc).fold(0.0, f64::max);
    let points = |j: usize, i: usize| (origin[0] + i as f64 * spacing, origin[1] + j as f64 * spacing);
    let raw: Vec<Vec<f64>> = (0..ny).map(|j| (0..nx).map(|i| { let (x, y) = points(j, i); cap_height(x, y) }).collect()).collect();
    let full: Vec<f64> = (0..ny).flat_map(|j| (0..nx).map(move |i| (j, i))).filter(|&(j, i)| { let (x, y) = points(j, i); x.hypot(y) >= ROUGH_FULL_RADIUS }).map(|(j, i)| raw[j][i]).collect();
    let mean = full.iter().sum::<f64>() / full.len() as f64;
    let measured = (full.iter().map(|z| (z - mean).powi(2)).sum::<f64>() / full.len() as f64).sqrt();
    let scale = rms / measured;
    let heights: Vec<Vec<f64>> = (0..ny).map(|j| (0..nx).map(|i| { let (x, y) = points(j, i); scale * raw[j][i] * fade(x.hypot(y), ROUGH_FLAT_RADIUS, ROUGH_FULL_RADIUS) }).collect()).collect();
    grid_triangles(origin, spacing, &heights)
}

/// The rough ground of the PhantomX Mark II's free gait (`phantomx_free_gait_rough.toml`):
/// AMRU5's ([`rough`], seed 7) a third of its size, 0.5 cm RMS over wavelengths of 0.1-1 m on
/// a 3.3 cm grid (a 5.3 m × 4 m field), flat within 0.3 m of the origin, fully rough beyond
/// 0.6 m.
///
/// INTERPRETATION: the PhantomX stands about three times lower than AMRU5 (body 0.12 m above
/// the ground against 0.41 m) and lifts its feet 3 cm (AMRU5 4.5 cm on rough ground): the
/// heights and the wavelengths are scaled by 1/3 (1.5 cm RMS → 0.5 cm; the shortest wavelength
/// stays about half the foot spacing). Its feet stand up to about 0.25 m from the body centre
/// (AMRU5 0.54 m): flat within 0.3 m, with AMRU5's fade to twice that radius.
pub const PHANTOMX_ROUGH: RoughGround = RoughGround { rms: 0.005, seed: 7, length_scale: 1.0 / 3.0, flat_radius: 0.3, full_radius: 0.6 };

/// The format of the shipped files: binary little endian with float coordinates, as Blender
/// exports.
pub const SHIPPED_FORMAT: PlyFormat = PlyFormat { encoding: Encoding::BinaryLittleEndian, double: false };

/// The shipped terrains, by file name.
pub fn shipped() -> Vec<(&'static str, Triangles)> {
    vec![
        ("step_8cm.ply", step_block(0.08)),
        ("slope_20deg.ply", ramp(20f64.to_radians())),
        ("rough_ground.ply", rough(0.015, 7)),
        ("rough_ground_phantomx.ply", PHANTOMX_ROUGH.triangles()),
    ]
}
