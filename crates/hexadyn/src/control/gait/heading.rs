//! Heading velocities (V_x, V_y, Ω_z) in the global frame (thesis Section 7.2.4, Eq. 7.4-7.5):
//! constant, a CSV time series, and the paths of Section 7.5.3.

use std::path::Path;

use nalgebra::Vector3;

/// Global linear velocity (m/s) and yaw rate (rad/s) commanded at an instant.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct Heading {
    pub velocity: Vector3<f64>,
    pub yaw_rate: f64,
}

impl Heading {
    pub fn new(vx: f64, vy: f64, yaw_rate: f64) -> Self {
        Heading { velocity: Vector3::new(vx, vy, 0.0), yaw_rate }
    }

    /// Commanded global velocity of a point rigidly attached to the body at `r` from its centre
    /// (global frame): v_C = v_b + ω × p_{C/b} (Eq. 7.25) with ω = (0, 0, Ω_z).
    pub fn point_velocity(&self, r: &Vector3<f64>) -> Vector3<f64> {
        self.velocity + Vector3::new(0.0, 0.0, self.yaw_rate).cross(r)
    }
}

/// Where the heading velocities come from.
pub trait HeadingSource: Send {
    fn heading(&mut self, t: f64) -> Heading;

    /// Instants of the control grid k·dt in [0, end] among which the largest |v| + |Ω_z| r of
    /// the run is found, for any arm r >= 0: few (independent of `end / dt`) where the heading
    /// is piecewise linear in time, whose maximum of that convex function lies at a knot.
    fn extreme_times(&self, end: f64, dt: f64) -> Vec<f64>;
}

/// The control instants k·dt on either side of each knot in [0, end], with the first and the
/// last instant: a piecewise-linear heading takes its extremes there.
fn instants_beside(knots: impl Iterator<Item = f64>, end: f64, dt: f64) -> Vec<f64> {
    let last = (end / dt).round();
    let mut ks: Vec<f64> = vec![0.0, last];
    for knot in knots.filter(|&k| k >= 0.0 && k <= end) {
        let k = knot / dt;
        ks.extend([k.floor().clamp(0.0, last), k.ceil().clamp(0.0, last)]);
    }
    ks.sort_by(f64::total_cmp);
    ks.dedup();
    ks.into_iter().map(|k| k * dt).collect()
}

/// Constant heading velocities.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Constant(pub Heading);

impl HeadingSource for Constant {
    fn heading(&mut self, _t: f64) -> Heading {
        self.0
    }

    fn extreme_times(&self, _end: f64, _dt: f64) -> Vec<f64> {
        vec![0.0]
    }
}

/// Piecewise-constant headings: each (start time, heading) holds until the next start.
/// The back-and-forth path (V_x = 0.015 m/s, then −0.02 m/s from t = 140 s) and the straight
/// lines with sharp direction changes of Section 7.5.3 are of this kind.
#[derive(Clone, Debug, PartialEq)]
pub struct Segments(pub Vec<(f64, Heading)>);

impl Segments {
    /// Section 7.5.3: V_x = 0.015 m/s, then −0.02 m/s from t = 140 s.
    pub fn back_and_forth() -> Self {
        Segments(vec![(0.0, Heading::new(0.015, 0.0, 0.0)), (140.0, Heading::new(-0.02, 0.0, 0.0))])
    }
    /// Straight lines with sharp 90° direction changes and zero yaw rate (Section 7.5.3, Fig.
    /// 7.13 is lost: a square of `side` metres at `speed` m/s).
    pub fn square(side: f64, speed: f64) -> Self {
        let leg = side / speed;
        let dirs = [(1.0, 0.0), (0.0, 1.0), (-1.0, 0.0), (0.0, -1.0)];
        Segments(dirs.iter().enumerate().map(|(i, (x, y))| (i as f64 * leg, Heading::new(x * speed, y * speed, 0.0))).collect())
    }
}

impl HeadingSource for Segments {
    fn heading(&mut self, t: f64) -> Heading {
        self.0.iter().take_while(|(start, _)| *start <= t).last().map_or(Heading::default(), |(_, h)| *h)
    }

    fn extreme_times(&self, end: f64, dt: f64) -> Vec<f64> {
        instants_beside(self.0.iter().map(|(start, _)| *start), end, dt)
    }
}

/// A time series of headings, linearly interpolated, held constant beyond its ends.
#[derive(Clone, Debug, PartialEq)]
pub struct Series {
    pub t: Vec<f64>,
    pub headings: Vec<Heading>,
}

/// A malformed heading file: which file, where, and what is allowed.
#[derive(Clone, Debug, PartialEq, thiserror::Error)]
#[error("{file}:{line}: {problem}")]
pub struct SeriesError {
    pub file: String,
    pub line: usize,
    pub problem: String,
}

impl Series {
    /// Reads a CSV file with the header `t,vx,vy,omega_z` (s, m/s, m/s, rad/s), times strictly
    /// increasing (the `csv` crate, [`crate::fields::csv_records`]: lines starting with `#`
    /// are comments).
    pub fn from_csv(path: &Path) -> Result<Self, SeriesError> {
        let file = path.display().to_string();
        let err = |line: usize, problem: String| SeriesError { file: file.clone(), line, problem };
        let text = crate::fields::read_input(path).map_err(|e| err(0, format!("cannot read: {e}")))?;
        let mut records = crate::fields::csv_records(&text, true).map_err(|(line, e)| err(line, e))?.into_iter();
        let (n, header) = records.next().ok_or_else(|| err(1, "empty file; expected the header t,vx,vy,omega_z".into()))?;
        if header != ["t", "vx", "vy", "omega_z"] {
            return Err(err(n, format!("header {:?}; expected t,vx,vy,omega_z", header.join(","))));
        }
        let mut series = Series { t: Vec::new(), headings: Vec::new() };
        for (n, fields) in records {
            let values: Vec<f64> = fields.iter().map(|v| v.parse::<f64>().map_err(|_| err(n, format!("value {v:?} is not a number")))).collect::<Result<_, _>>()?;
            if values.len() != 4 {
                return Err(err(n, format!("{} values; expected 4 (t, vx, vy, omega_z)", values.len())));
            }
            if let Some(v) = values.iter().find(|v| !v.is_finite()) {
                return Err(err(n, format!("value {v} is not finite")));
            }
            if series.t.last().is_some_and(|&last| values[0] <= last) {
                return Err(err(n, format!("t = {} does not increase", values[0])));
            }
            series.t.push(values[0]);
            series.headings.push(Heading::new(values[1], values[2], values[3]));
        }
        if series.t.is_empty() {
            return Err(err(n, "no data rows".into()));
        }
        Ok(series)
    }
}

impl HeadingSource for Series {
    fn heading(&mut self, t: f64) -> Heading {
        let i = self.t.partition_point(|&x| x <= t);
        if i == 0 {
            return self.headings[0];
        }
        if i == self.t.len() {
            return self.headings[i - 1];
        }
        let (a, b) = (&self.headings[i - 1], &self.headings[i]);
        let s = (t - self.t[i - 1]) / (self.t[i] - self.t[i - 1]);
        Heading { velocity: a.velocity + (b.velocity - a.velocity) * s, yaw_rate: a.yaw_rate + (b.yaw_rate - a.yaw_rate) * s }
    }

    fn extreme_times(&self, end: f64, dt: f64) -> Vec<f64> {
        instants_beside(self.t.iter().copied(), end, dt)
    }
}

/// A planar path through waypoints, a natural cubic spline in time per coordinate, traveled
/// with the body yaw tangent to the path (Section 7.5.3): V_x, V_y and Ω_z all vary.
#[derive(Clone, Debug, PartialEq)]
pub struct Spline {
    x: CubicSpline,
    y: CubicSpline,
}

impl Spline {
    /// Waypoints (x, y) in metres reached at the times `t` (s).
    pub fn new(t: &[f64], x: &[f64], y: &[f64]) -> Self {
        Spline { x: CubicSpline::natural(t, x), y: CubicSpline::natural(t, y) }
    }
    /// The same path turned about its first waypoint so that it starts along +x: a robot
    /// starting with zero yaw then keeps its yaw tangent to the path.
    pub fn starting_along_x(t: &[f64], x: &[f64], y: &[f64]) -> Self {
        let raw = Spline::new(t, x, y);
        let (_, _, yaw0) = raw.pose(t[0]);
        let (s, c) = (-yaw0).sin_cos();
        let xr: Vec<f64> = x.iter().zip(y).map(|(a, b)| c * (a - x[0]) - s * (b - y[0])).collect();
        let yr: Vec<f64> = x.iter().zip(y).map(|(a, b)| s * (a - x[0]) + c * (b - y[0])).collect();
        Spline::new(t, &xr, &yr)
    }
    /// Section 7.5.3's spline (Fig. 7.13 is lost): a winding path of about 2.2 m in 200 s,
    /// speed below 2 cm/s, with V_x, V_y and Ω_z all varying.
    pub fn section_7_5_3() -> Self {
        Spline::starting_along_x(&[0.0, 50.0, 100.0, 150.0, 200.0], &[0.0, 0.6, 1.1, 1.5, 2.0], &[0.0, 0.2, -0.1, -0.45, -0.3])
    }
    /// Position and yaw (tangent) at t.
    pub fn pose(&self, t: f64) -> (f64, f64, f64) {
        let (dx, dy) = (self.x.derivative(t).0, self.y.derivative(t).0);
        (self.x.value(t), self.y.value(t), dy.atan2(dx))
    }
}

impl HeadingSource for Spline {
    fn heading(&mut self, t: f64) -> Heading {
        let (dx, ddx) = self.x.derivative(t);
        let (dy, ddy) = self.y.derivative(t);
        let speed2 = dx * dx + dy * dy;
        // Ω_z = d/dt atan2(ẏ, ẋ).
        let yaw_rate = if speed2 > 0.0 { (dx * ddy - dy * ddx) / speed2 } else { 0.0 };
        Heading::new(dx, dy, yaw_rate)
    }

    /// Between knots the heading is not linear: every control instant, but at most
    /// [`SPLINE_SAMPLES`] evenly spread instants per knot interval.
    fn extreme_times(&self, end: f64, dt: f64) -> Vec<f64> {
        let knots = &self.x.t;
        let mut times = instants_beside(knots.iter().copied(), end, dt);
        for w in knots.windows(2) {
            let (a, b) = (w[0].max(0.0), w[1].min(end));
            let (ka, kb) = ((a / dt).ceil(), (b / dt).floor());
            if kb < ka {
                continue;
            }
            let n = kb - ka;
            let stride = (n / SPLINE_SAMPLES as f64).ceil().max(1.0);
            let mut k = ka;
            while k <= kb {
                times.push(k * dt);
                k += stride;
            }
        }
        times.sort_by(f64::total_cmp);
        times.dedup();
        times
    }
}

/// Samples per knot interval of the stride check on a spline path (the 50 s intervals of the
/// built-in path at 100 Hz have 5000 instants: every 3rd is taken).
pub const SPLINE_SAMPLES: usize = 2000;

/// Natural cubic spline of one coordinate (second derivative zero at the ends).
#[derive(Clone, Debug, PartialEq)]
struct CubicSpline {
    t: Vec<f64>,
    y: Vec<f64>,
    /// Second derivatives at the knots.
    m: Vec<f64>,
}

impl CubicSpline {
    fn natural(t: &[f64], y: &[f64]) -> Self {
        let n = t.len();
        assert!(n >= 2 && y.len() == n, "a spline needs at least two knots");
        // Tridiagonal system for the second derivatives (Thomas algorithm).
        let mut m = vec![0.0; n];
        if n > 2 {
            let h: Vec<f64> = t.windows(2).map(|w| w[1] - w[0]).collect();
            let k = n - 2;
            let (mut diag, mut upper, mut rhs) = (vec![0.0; k], vec![0.0; k], vec![0.0; k]);
            for i in 0..k {
                diag[i] = 2.0 * (h[i] + h[i + 1]);
                upper[i] = h[i + 1];
                rhs[i] = 6.0 * ((y[i + 2] - y[i + 1]) / h[i + 1] - (y[i + 1] - y[i]) / h[i]);
            }
            for i in 1..k {
                let w = h[i] / diag[i - 1];
                diag[i] -= w * upper[i - 1];
                rhs[i] -= w * rhs[i - 1];
            }
            m[k] = rhs[k - 1] / diag[k - 1];
            for i in (0..k - 1).rev() {
                m[i + 1] = (rhs[i] - upper[i] * m[i + 2]) / diag[i];
            }
        }
        CubicSpline { t: t.to_vec(), y: y.to_vec(), m }
    }

    fn segment(&self, t: f64) -> (usize, f64, f64) {
        let i = self.t.partition_point(|&x| x <= t).clamp(1, self.t.len() - 1) - 1;
        let h = self.t[i + 1] - self.t[i];
        (i, h, t.clamp(self.t[0], *self.t.last().expect("knots")) - self.t[i])
    }

    fn value(&self, t: f64) -> f64 {
        let (i, h, s) = self.segment(t);
        let (a, b) = ((h - s) / h, s / h);
        a * self.y[i] + b * self.y[i + 1] + ((a * a * a - a) * self.m[i] + (b * b * b - b) * self.m[i + 1]) * h * h / 6.0
    }

    /// First and second derivatives; zero velocity beyond the last knot.
    fn derivative(&self, t: f64) -> (f64, f64) {
        if t >= *self.t.last().expect("knots") || t < self.t[0] {
            return (0.0, 0.0);
        }
        let (i, h, s) = self.segment(t);
        let (a, b) = ((h - s) / h, s / h);
        let d1 = (self.y[i + 1] - self.y[i]) / h + (-(3.0 * a * a - 1.0) * self.m[i] + (3.0 * b * b - 1.0) * self.m[i + 1]) * h / 6.0;
        let d2 = a * self.m[i] + b * self.m[i + 1];
        (d1, d2)
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use approx::assert_relative_eq;

    #[test]
    fn segments_switch_at_their_start_times() {
        let mut s = Segments::back_and_forth();
        assert_eq!(s.heading(139.99).velocity.x, 0.015);
        assert_eq!(s.heading(140.0).velocity.x, -0.02);
        let mut sq = Segments::square(1.0, 0.02);
        assert_eq!(sq.heading(60.0).velocity, Vector3::new(0.0, 0.02, 0.0));
    }

    /// The spline interpolates its knots; integrating its headings follows its positions; the
    /// yaw rate is the derivative of the tangent angle.
    #[test]
    fn spline_headings_integrate_to_the_path() {
        let t = [0.0, 100.0, 200.0, 300.0, 400.0];
        let (x, y) = ([0.0, 1.0, 2.0, 2.5, 3.5], [0.0, 0.5, 0.0, -0.6, -0.4]);
        let mut s = Spline::new(&t, &x, &y);
        for i in 0..5 {
            let (px, py, _) = s.pose(t[i]);
            assert_relative_eq!(px, x[i], epsilon = 1e-12);
            assert_relative_eq!(py, y[i], epsilon = 1e-12);
        }
        let dt = 0.01;
        let (mut px, mut py, mut yaw) = s.pose(0.0);
        let mut previous = s.heading(0.0);
        for k in 1..=39999 {
            let h = s.heading(k as f64 * dt);
            px += 0.5 * (previous.velocity.x + h.velocity.x) * dt;
            py += 0.5 * (previous.velocity.y + h.velocity.y) * dt;
            yaw += 0.5 * (previous.yaw_rate + h.yaw_rate) * dt;
            previous = h;
        }
        let (ex, ey, eyaw) = s.pose(399.99);
        assert_relative_eq!(px, ex, epsilon = 1e-5);
        assert_relative_eq!(py, ey, epsilon = 1e-5);
        assert_relative_eq!(yaw, eyaw, epsilon = 1e-3);
    }

    #[test]
    fn built_in_spline_starts_along_x_below_two_cm_per_second() {
        let mut s = Spline::section_7_5_3();
        assert!(s.pose(0.0).2.abs() < 1e-12);
        let speeds: Vec<f64> = (0..2000).map(|i| s.heading(i as f64 * 0.1).velocity.norm()).collect();
        assert!(speeds.iter().all(|&v| v < 0.02), "{:?}", speeds.iter().cloned().fold(0.0, f64::max));
        assert!((0..200).any(|i| s.heading(i as f64).yaw_rate.abs() > 1e-4));
    }

    #[test]
    fn csv_series_reads_and_reports_errors() {
        let dir = std::env::temp_dir().join(format!("hexadyn-heading-{}", std::process::id()));
        std::fs::create_dir_all(&dir).unwrap();
        let good = dir.join("good.csv");
        std::fs::write(&good, "t,vx,vy,omega_z\n0,0.01,0,0\n10,0.02,0.01,0.001\n").unwrap();
        let mut s = Series::from_csv(&good).unwrap();
        assert_relative_eq!(s.heading(5.0).velocity.x, 0.015, epsilon = 1e-15);
        assert_relative_eq!(s.heading(50.0).yaw_rate, 0.001);
        let bad = dir.join("bad.csv");
        std::fs::write(&bad, "t,vx,vy,omega_z\n0,0.01,0,0\n0,0.02,x,0\n").unwrap();
        let e = Series::from_csv(&bad).unwrap_err().to_string();
        assert!(e.contains("bad.csv:3") && e.contains("\"x\" is not a number"), "{e}");
        std::fs::write(&bad, "t,vx,vy,omega_z\n1,0.01,0,0\n1,0.02,0,0\n").unwrap();
        assert!(Series::from_csv(&bad).unwrap_err().to_string().contains("does not increase"));
        std::fs::remove_dir_all(&dir).unwrap();
    }
}
