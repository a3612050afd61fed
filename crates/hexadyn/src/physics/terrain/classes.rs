//! Seeded terrain classes for campaigns over seeds (issue 11's terrain-class benchmark): a step
//! of a given rise, a slope of a given angle, rough ground of a given RMS height, each drawn
//! from a seed. The robot starts at the origin heading along +x with its feet on a circle of
//! about [`FOOT_CIRCLE_RADIUS`] around the body centre ([`super::generate`]'s module docs).
//!
//! What the seed varies (INTERPRETATION, beyond the thesis: Section 7.7.5 shows one terrain of
//! each kind; a class is the set of placements a robot walking straight ahead may meet):
//! - step: whether it goes up or down (even chance), the direction of its edge, whose normal
//!   makes an angle uniform in [-30°, 30°] with the heading (the robot meets it square or
//!   obliquely, so that the legs reach it one after another), and the gap between the edge and
//!   the start foot nearest to it, uniform in [0.05, 0.25] m (the edge is met at any phase of
//!   the gait). The edge runs across the whole path: every leg crosses it.
//! - slope: an infinite plane through the origin whose uphill direction makes an angle uniform
//!   in [0, 360°) with the heading (the robot climbs, descends, traverses or walks obliquely);
//!   the robot starts on it.
//! - rough: the field of [`super::generate::rough`] drawn from the seed (64 cosine waves of
//!   random direction, wavelength and phase), flat within 0.6 m of the start and fully rough
//!   beyond 1.2 m.
//! - stairs (issue 37): [`STAIRS_RISERS`] risers of the class's height, up or down as the class
//!   says, placed as a step's edge (the seed draws the obliquity and the gap the same way) with
//!   a tread depth uniform in [`STAIRS_TREAD`]. INTERPRETATION: AMRU5's feet stand 0.94 m
//!   apart fore and aft; treads of 0.3-0.6 m put its front, middle and hind feet on different
//!   levels, the case that breaks a gait which assumes one ground plane.
//! - ramp and drop (issue 37): a ramp of [`RAMP_ANGLE`] rising [`RAMP_RISE`] from where a step's
//!   edge would be, a landing of depth uniform in [`STAIRS_TREAD`], then a drop of the class's
//!   height (the robot meets the drop walking downhill from nothing but flat ground).
//! - boulders (issue 37): the field of [`super::generate::boulders`] drawn from the seed
//!   (spherical caps on flat ground), flat within 0.6 m of the start, full beyond 1.2 m.

use std::sync::Arc;

use nalgebra::Vector3;
use rand::{Rng, SeedableRng};
use rand_chacha::ChaCha8Rng;

use super::{generate, MeshError, MeshTerrain, Slope, Step, Terrain};

/// Radius of the circle the feet start on, around the body centre (m): the workspace centres
/// of AMRU5 ([`super::generate`]'s module docs: 0.47 m ahead and behind, 0.27-0.54 m aside).
pub const FOOT_CIRCLE_RADIUS: f64 = 0.54;

/// Largest angle between the heading and a step edge's normal (rad): 30°.
pub const STEP_OBLIQUITY_MAX: f64 = std::f64::consts::FRAC_PI_6;

/// Range of the gap between the edge and the nearest start foot (m).
pub const STEP_GAP: std::ops::Range<f64> = 0.05..0.25;

/// Risers of a staircase.
pub const STAIRS_RISERS: usize = 3;

/// Range of the depth of a staircase's treads and of a ramp's landing (m).
pub const STAIRS_TREAD: std::ops::Range<f64> = 0.3..0.6;

/// Inclination of the ramp before a drop (rad): issue 37's 15°.
pub const RAMP_ANGLE: f64 = 15.0 * std::f64::consts::PI / 180.0;

/// Height the ramp before a drop rises (m): above the largest drop of the classes (8 cm), so
/// that the ground beyond the drop stays above the start level.
pub const RAMP_RISE: f64 = 0.1;

/// A class of terrain, by the size of its feature.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum TerrainClass {
    /// A step of this rise (m); a rise of 0 is flat ground.
    Step { rise: f64 },
    /// A plane of this inclination (rad).
    Slope { angle: f64 },
    /// Rough ground of this RMS height (m).
    Rough { rms: f64 },
    /// A staircase of [`STAIRS_RISERS`] risers of this height (m), up or down.
    Stairs { riser: f64, up: bool },
    /// A ramp up to a landing that ends in a drop of this height (m).
    RampDrop { drop: f64 },
    /// A boulder field of this RMS height (m).
    Boulders { rms: f64 },
}

/// The obliquity of an edge's normal from the heading and the gap between the edge and the
/// nearest start foot, drawn as for a step ([`STEP_OBLIQUITY_MAX`], [`STEP_GAP`]).
fn edge_placement(rng: &mut ChaCha8Rng) -> (f64, f64) {
    let obliquity = rng.random_range(-STEP_OBLIQUITY_MAX..=STEP_OBLIQUITY_MAX);
    (obliquity, rng.random_range(STEP_GAP))
}

/// A ground of level heights z = levels[k] between the edges u = edges[k - 1] and edges[k]
/// (u along the edges' normal, at `obliquity` from +x), joined by vertical faces, or by a
/// slope where `runs` gives an edge's horizontal run; it covers the robot's straight path
/// along +x for `length` (m) and its surroundings.
fn levels_across(edges: &[f64], runs: &[f64], levels: &[f64], obliquity: f64, length: f64) -> Result<MeshTerrain, MeshError> {
    // In the edges' frame the path runs within |v| <= length sin 30° of the axis; 1.5 m more
    // on every side holds the feet and the ground's margin.
    let (u0, u1, half) = (-2.0, length + 2.0, length * STEP_OBLIQUITY_MAX.sin() + 1.5);
    let mut xs = vec![u0];
    let mut zs = vec![levels[0]];
    for (k, (&edge, &run)) in edges.iter().zip(runs).enumerate() {
        xs.extend([edge, edge + run]);
        zs.extend([levels[k], levels[k + 1]]);
    }
    xs.push(u1);
    zs.push(*levels.last().expect("one level or more"));
    MeshTerrain::new(generate::rotated(generate::profile(&xs, &zs, (-half, half)), obliquity))
}

/// One terrain of a class, drawn from a seed.
#[derive(Clone, Debug)]
pub struct SeededTerrain {
    pub terrain: Arc<dyn Terrain>,
    /// Unit normal of the plane the ground follows at large: the slope's, vertical for steps
    /// and rough ground. The body's attitude is judged against it.
    pub nominal_normal: Vector3<f64>,
    /// The distance the body walks along the heading until every foot has crossed the
    /// feature (m): for a step, every foot beyond its edge; on rough ground, every foot in the
    /// fully rough region; on the unbounded slope, one foot-circle diameter (every foot has
    /// left its start point for a new foothold).
    pub crossing_m: f64,
    /// What the seed drew, for the record.
    pub drawn: String,
}

impl TerrainClass {
    /// The terrain of this class drawn from `seed`.
    pub fn generate(&self, seed: u64) -> Result<SeededTerrain, MeshError> {
        let mut rng = ChaCha8Rng::seed_from_u64(seed);
        Ok(match *self {
            TerrainClass::Step { rise } => {
                let up = rng.random_bool(0.5);
                let obliquity = rng.random_range(-STEP_OBLIQUITY_MAX..=STEP_OBLIQUITY_MAX);
                let gap = rng.random_range(STEP_GAP);
                // The edge's normal u at `obliquity` from +x: feet within the foot circle lie at
                // most R ahead of the body centre along u, so the edge is at R + gap along u.
                // INTERPRETATION: the foot circle bounds the feet, so the gap to the nearest
                // foot is at least `gap` (exactly for a foot on u's diameter).
                let edge = FOOT_CIRCLE_RADIUS + gap;
                // Up: the high side beyond the edge; down: the robot stands on the high side.
                let (azimuth, edge_along, base) = if up { (obliquity, edge, 0.0) } else { (obliquity + std::f64::consts::PI, -edge, -rise) };
                let terrain: Arc<dyn Terrain> = if rise > 0.0 { Arc::new(Step { base, rise, edge: edge_along, azimuth }) } else { Arc::new(super::FlatGround { height: 0.0 }) };
                // Every foot beyond the edge: the body centre at edge + R along u.
                let crossing_m = (edge + FOOT_CIRCLE_RADIUS) / obliquity.cos();
                let drawn = format!("{} {:.0} mm, edge normal at {:+.1} deg, gap {:.0} mm", if up { "up" } else { "down" }, rise * 1e3, obliquity.to_degrees(), gap * 1e3);
                SeededTerrain { terrain, nominal_normal: Vector3::z(), crossing_m, drawn }
            }
            TerrainClass::Slope { angle } => {
                let azimuth = rng.random_range(0.0..std::f64::consts::TAU);
                let slope = Slope::from_angle(0.0, angle, azimuth);
                let normal = slope.height_normal(0.0, 0.0).1;
                let drawn = format!("{:.1} deg, uphill at {:.0} deg from the heading", angle.to_degrees(), azimuth.to_degrees());
                SeededTerrain { terrain: Arc::new(slope), nominal_normal: normal, crossing_m: 2.0 * FOOT_CIRCLE_RADIUS, drawn }
            }
            TerrainClass::Rough { rms } => {
                let seed = rng.random();
                let mesh = MeshTerrain::new(generate::rough(rms, seed))?;
                let drawn = format!("RMS {:.1} mm, field seed {seed}", rms * 1e3);
                SeededTerrain { terrain: Arc::new(mesh), nominal_normal: Vector3::z(), crossing_m: generate::ROUGH_FULL_RADIUS + FOOT_CIRCLE_RADIUS, drawn }
            }
            TerrainClass::Stairs { riser, up } => {
                let (obliquity, gap) = edge_placement(&mut rng);
                let tread = rng.random_range(STAIRS_TREAD);
                let first = FOOT_CIRCLE_RADIUS + gap;
                let edges: Vec<f64> = (0..STAIRS_RISERS).map(|k| first + k as f64 * tread).collect();
                let rise = if up { riser } else { -riser };
                let levels: Vec<f64> = (0..=STAIRS_RISERS).map(|k| k as f64 * rise).collect();
                // Every foot beyond the last edge: the body centre R beyond it along the normal.
                let crossing_m = (edges[STAIRS_RISERS - 1] + FOOT_CIRCLE_RADIUS) / obliquity.cos();
                let mesh = levels_across(&edges, &[0.0; STAIRS_RISERS], &levels, obliquity, crossing_m)?;
                let drawn = format!("{} {STAIRS_RISERS} x {:.0} mm, treads {:.0} mm, edge normal at {:+.1} deg, gap {:.0} mm", if up { "up" } else { "down" }, riser * 1e3, tread * 1e3, obliquity.to_degrees(), gap * 1e3);
                SeededTerrain { terrain: Arc::new(mesh), nominal_normal: Vector3::z(), crossing_m, drawn }
            }
            TerrainClass::RampDrop { drop } => {
                let (obliquity, gap) = edge_placement(&mut rng);
                let landing = rng.random_range(STAIRS_TREAD);
                let run = RAMP_RISE / RAMP_ANGLE.tan();
                let (foot, edge) = (FOOT_CIRCLE_RADIUS + gap, FOOT_CIRCLE_RADIUS + gap + run + landing);
                let crossing_m = (edge + FOOT_CIRCLE_RADIUS) / obliquity.cos();
                let mesh = levels_across(&[foot, edge], &[run, 0.0], &[0.0, RAMP_RISE, RAMP_RISE - drop], obliquity, crossing_m)?;
                let drawn = format!("drop {:.0} mm after a landing of {:.0} mm, edge normal at {:+.1} deg, gap {:.0} mm", drop * 1e3, landing * 1e3, obliquity.to_degrees(), gap * 1e3);
                SeededTerrain { terrain: Arc::new(mesh), nominal_normal: Vector3::z(), crossing_m, drawn }
            }
            TerrainClass::Boulders { rms } => {
                let seed = rng.random();
                let mesh = MeshTerrain::new(generate::boulders(rms, seed))?;
                let drawn = format!("RMS {:.1} mm, field seed {seed}", rms * 1e3);
                SeededTerrain { terrain: Arc::new(mesh), nominal_normal: Vector3::z(), crossing_m: generate::ROUGH_FULL_RADIUS + FOOT_CIRCLE_RADIUS, drawn }
            }
        })
    }

    /// The class's name with its size, e.g. `step 8 cm`.
    pub fn label(&self) -> String {
        match *self {
            TerrainClass::Step { rise } => format!("step {:.0} cm", rise * 100.0),
            TerrainClass::Slope { angle } => format!("slope {:.0} deg", angle.to_degrees()),
            TerrainClass::Rough { rms } => format!("rough {:.1} cm RMS", rms * 100.0),
            TerrainClass::Stairs { riser, up } => format!("stairs {} {:.0} cm", if up { "up" } else { "down" }, riser * 100.0),
            TerrainClass::RampDrop { drop } => format!("ramp drop {:.0} cm", drop * 100.0),
            TerrainClass::Boulders { rms } => format!("boulders {:.1} cm RMS", rms * 100.0),
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Heights of the ground along the heading (+x) at lateral offset `y`, from -1 to 3 m.
    fn profile(t: &dyn Terrain, y: f64) -> Vec<(f64, f64)> {
        (0..=4000).map(|i| -1.0 + i as f64 * 1e-3).map(|x| (x, t.height_normal(x, y).0)).collect()
    }

    #[test]
    fn a_step_rises_or_drops_by_its_rise_beyond_the_drawn_gap_and_is_crossed_within_the_distance() {
        let (mut ups, mut downs) = (0, 0);
        for seed in 0..40 {
            let rise = 0.08;
            let s = TerrainClass::Step { rise }.generate(seed).unwrap();
            let start = s.terrain.height_normal(0.0, 0.0).0;
            assert_eq!(start, 0.0, "seed {seed}: the robot starts at z = 0");
            // Every start foot (on the foot circle) stands on the start level, at least 5 cm
            // from the edge: the ground is level within R + 5 cm of the centre.
            for k in 0..72 {
                let a = k as f64 * 5f64.to_radians();
                let r = FOOT_CIRCLE_RADIUS + STEP_GAP.start - 1e-6;
                assert_eq!(s.terrain.height_normal(r * a.cos(), r * a.sin()).0, 0.0, "seed {seed}, {} deg", 5 * k);
            }
            // Along the heading the ground changes once, by the rise, before the crossing
            // distance minus R (where the hind feet are).
            let p = profile(s.terrain.as_ref(), 0.0);
            let changes: Vec<_> = p.windows(2).filter(|w| w[1].1 != w[0].1).collect();
            assert_eq!(changes.len(), 1, "seed {seed}: {changes:?}");
            let (x_edge, dz) = (changes[0][1].0, changes[0][1].1 - changes[0][0].1);
            assert!((dz.abs() - rise).abs() < 1e-12, "seed {seed}: the step is {dz} m");
            if dz > 0.0 { ups += 1 } else { downs += 1 }
            let gap = x_edge - FOOT_CIRCLE_RADIUS;
            assert!(gap >= STEP_GAP.start - 1e-3 && gap <= (STEP_GAP.end + FOOT_CIRCLE_RADIUS) / STEP_OBLIQUITY_MAX.cos() - FOOT_CIRCLE_RADIUS + 1e-3, "seed {seed}: edge at x = {x_edge}");
            // At the crossing distance the whole foot circle stands beyond the edge.
            for k in 0..72 {
                let a = k as f64 * 5f64.to_radians();
                let (x, y) = (s.crossing_m + 1e-9 + FOOT_CIRCLE_RADIUS * a.cos(), FOOT_CIRCLE_RADIUS * a.sin());
                assert!((s.terrain.height_normal(x, y).0 - dz).abs() < 1e-12, "seed {seed}: ({x}, {y}) not beyond the edge");
            }
        }
        assert!(ups >= 10 && downs >= 10, "{ups} up, {downs} down of 40");
        assert_eq!(TerrainClass::Step { rise: 0.0 }.generate(3).unwrap().terrain.height_normal(1.0, 0.3).0, 0.0);
    }

    /// The start: every foot on the foot circle (and 5 cm beyond) stands on level ground at 0;
    /// at the crossing distance the whole foot circle stands on `end`.
    fn starts_level_and_is_crossed_onto(s: &SeededTerrain, end: f64, seed: u64) {
        for k in 0..72 {
            let a = k as f64 * 5f64.to_radians();
            let r = FOOT_CIRCLE_RADIUS + STEP_GAP.start - 1e-6;
            assert!(s.terrain.height_normal(r * a.cos(), r * a.sin()).0.abs() < 1e-9, "seed {seed}, {} deg", 5 * k);
            let (x, y) = (s.crossing_m + 1e-6 + FOOT_CIRCLE_RADIUS * a.cos(), FOOT_CIRCLE_RADIUS * a.sin());
            assert!((s.terrain.height_normal(x, y).0 - end).abs() < 1e-9, "seed {seed}: ({x}, {y}) not on the far level {end}");
        }
    }

    #[test]
    fn stairs_rise_or_descend_by_their_risers_one_tread_apart() {
        for (seed, up) in (0..20).map(|seed| (seed, seed % 2 == 0)) {
            let riser = 0.06;
            let s = TerrainClass::Stairs { riser, up }.generate(seed).unwrap();
            let sign = if up { 1.0 } else { -1.0 };
            starts_level_and_is_crossed_onto(&s, sign * riser * STAIRS_RISERS as f64, seed);
            // Along the heading: three changes of one riser each, in the stair's direction,
            // a tread apart (measured along +x: the tread over the cosine of the obliquity).
            let p = profile(s.terrain.as_ref(), 0.0);
            let changes: Vec<(f64, f64)> = p.windows(2).filter(|w| (w[1].1 - w[0].1).abs() > 1e-9).map(|w| (w[1].0, w[1].1 - w[0].1)).collect();
            assert_eq!(changes.len(), STAIRS_RISERS, "seed {seed}: {changes:?}");
            assert!(changes.iter().all(|&(_, dz)| (dz - sign * riser).abs() < 1e-9), "seed {seed}: {changes:?}");
            let treads: Vec<f64> = changes.windows(2).map(|w| w[1].0 - w[0].0).collect();
            assert!((treads[0] - treads[1]).abs() < 2e-3, "seed {seed}: {treads:?}");
            let cos_max = STEP_OBLIQUITY_MAX.cos();
            assert!(treads[0] >= STAIRS_TREAD.start - 2e-3 && treads[0] <= STAIRS_TREAD.end / cos_max + 2e-3, "seed {seed}: {treads:?}");
        }
    }

    #[test]
    fn a_ramp_climbs_at_its_angle_to_a_landing_that_ends_in_the_drop() {
        for seed in 0..10 {
            let drop = 0.08;
            let s = TerrainClass::RampDrop { drop }.generate(seed).unwrap();
            starts_level_and_is_crossed_onto(&s, RAMP_RISE - drop, seed);
            let p = profile(s.terrain.as_ref(), 0.0);
            assert!((p.iter().map(|&(_, z)| z).fold(f64::MIN, f64::max) - RAMP_RISE).abs() < 1e-9, "seed {seed}: the landing is not at {RAMP_RISE} m");
            // The steepest rise along the path is at most the ramp's (at its angle when met
            // square, less when met obliquely), and one drop of the class's height.
            let slopes: Vec<f64> = p.windows(2).map(|w| (w[1].1 - w[0].1) / (w[1].0 - w[0].0)).collect();
            let steepest = slopes.iter().copied().filter(|g| *g < 1.0).fold(0.0, f64::max);
            assert!(steepest <= RAMP_ANGLE.tan() + 1e-9 && steepest >= RAMP_ANGLE.tan() * STEP_OBLIQUITY_MAX.cos() - 1e-9, "seed {seed}: {steepest}");
            let drops: Vec<f64> = p.windows(2).map(|w| w[1].1 - w[0].1).filter(|dz| *dz < -1e-3).collect();
            assert!(drops.len() == 1 && (drops[0] + drop).abs() < 1e-9, "seed {seed}: {drops:?}");
        }
    }

    #[test]
    fn boulder_fields_have_their_rms_height_beyond_the_start_and_differ_by_seed() {
        for (seed, rms) in [(0, 0.01), (1, 0.03)] {
            let s = TerrainClass::Boulders { rms }.generate(seed).unwrap();
            // The whole field beyond the fade (x in [-2, 6] m, y in [-2.5, 2.5] m), between the
            // grid's vertices.
            let heights: Vec<f64> = (0..160)
                .flat_map(|i| (0..100).map(move |j| (-1.99 + i as f64 * 0.05, -2.49 + j as f64 * 0.05)))
                .filter(|(x, y)| x.hypot(*y) >= generate::ROUGH_FULL_RADIUS)
                .map(|(x, y)| s.terrain.height_normal(x, y).0)
                .collect();
            let mean = heights.iter().sum::<f64>() / heights.len() as f64;
            let measured = (heights.iter().map(|h| (h - mean).powi(2)).sum::<f64>() / heights.len() as f64).sqrt();
            assert!((measured / rms - 1.0).abs() < 0.15, "seed {seed}: RMS {measured} m, asked {rms} m");
            // Boulders on flat ground: the ground between them is at 0, none below it.
            assert!(heights.iter().all(|&h| h >= -1e-12) && heights.iter().filter(|&&h| h < 1e-9).count() > heights.len() / 4, "seed {seed}");
            assert!(s.terrain.height_normal(0.3, 0.2).0.abs() < 1e-12);
        }
        let line = |seed| profile(TerrainClass::Boulders { rms: 0.02 }.generate(seed).unwrap().terrain.as_ref(), 0.5);
        assert_ne!(line(4), line(5));
        assert_eq!(line(4), line(4));
    }

    #[test]
    fn a_slope_has_its_angle_in_a_drawn_direction() {
        let angle = 20f64.to_radians();
        let azimuths: Vec<f64> = (0..20)
            .map(|seed| {
                let s = TerrainClass::Slope { angle }.generate(seed).unwrap();
                assert!((s.nominal_normal.z.acos() - angle).abs() < 1e-12);
                // The height difference over 1 m along the uphill direction is tan(angle).
                let up = Vector3::new(-s.nominal_normal.x, -s.nominal_normal.y, 0.0).normalize();
                let h = |d: f64| s.terrain.height_normal(d * up.x, d * up.y).0;
                assert!((h(1.0) - h(0.0) - angle.tan()).abs() < 1e-12);
                up.y.atan2(up.x)
            })
            .collect();
        // Drawn over every direction: some uphill ahead, some behind, some to the sides.
        for quadrant in 0..4 {
            let centre = quadrant as f64 * std::f64::consts::FRAC_PI_2;
            assert!(azimuths.iter().any(|a| ((a - centre + std::f64::consts::PI).rem_euclid(std::f64::consts::TAU) - std::f64::consts::PI).abs() < std::f64::consts::FRAC_PI_4), "quadrant {quadrant}: {azimuths:?}");
        }
    }

    #[test]
    fn rough_ground_has_its_rms_height_where_fully_rough_and_differs_by_seed() {
        for (seed, rms) in [(0, 0.01), (1, 0.02), (2, 0.03)] {
            let s = TerrainClass::Rough { rms }.generate(seed).unwrap();
            // Heights on a 5 cm grid of the fully rough part of the path's surroundings.
            let heights: Vec<f64> = (0..200)
                .flat_map(|i| (0..120).map(move |j| (2.0 + i as f64 * 0.05, -3.0 + j as f64 * 0.05)))
                .map(|(x, y)| s.terrain.height_normal(x, y).0)
                .collect();
            let mean = heights.iter().sum::<f64>() / heights.len() as f64;
            let measured = (heights.iter().map(|h| (h - mean).powi(2)).sum::<f64>() / heights.len() as f64).sqrt();
            assert!((measured / rms - 1.0).abs() < 0.15, "seed {seed}: RMS {measured} m, asked {rms} m");
            // Flat at the start.
            assert!(s.terrain.height_normal(0.3, 0.2).0.abs() < 1e-12);
        }
        let h = |seed| TerrainClass::Rough { rms: 0.02 }.generate(seed).unwrap().terrain.height_normal(3.0, 0.5).0;
        assert_eq!(h(4), h(4));
        assert_ne!(h(4), h(5));
    }
}
