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

/// A class of terrain, by the size of its feature.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum TerrainClass {
    /// A step of this rise (m); a rise of 0 is flat ground.
    Step { rise: f64 },
    /// A plane of this inclination (rad).
    Slope { angle: f64 },
    /// Rough ground of this RMS height (m).
    Rough { rms: f64 },
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
        })
    }

    /// The class's name with its size, e.g. `step 8 cm`.
    pub fn label(&self) -> String {
        match *self {
            TerrainClass::Step { rise } => format!("step {:.0} cm", rise * 100.0),
            TerrainClass::Slope { angle } => format!("slope {:.0} deg", angle.to_degrees()),
            TerrainClass::Rough { rms } => format!("rough {:.1} cm RMS", rms * 100.0),
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
