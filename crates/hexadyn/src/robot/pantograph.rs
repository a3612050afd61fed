//! The pantograph leg mechanism (thesis Section 3.4.1, Fig. 3.8, NOTES.md): dependent
//! parameters p0, p1 of Eq. 3.53-3.63 and the planar linkage A-B-C, B-D, D-E, C-E-F.
//!
//! Leg-plane coordinates (x radial outward, z up) have their origin at the crossing point C*.
//! A = (0, q_v) is driven by the vertical nut, D = (q_h, 0) by the horizontal one; in triangle
//! A-B-D the sides are c = AB, l = BD and k = AD (the triangle "klc" of Eq. 3.57-3.63).

use nalgebra::Vector2;

use crate::mbs::{DependentFunction, DualNum, Jet};

/// Lengths of the pantograph (Table 2.1, B.1), in metres.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct PantographGeometry {
    /// AC = L0, upper link.
    pub l0: f64,
    /// BD = CE = L1 = l, left link.
    pub l1: f64,
    /// DE = BC = L2, lower link.
    pub l2: f64,
    /// CF = L3, from the upper joint C to the foot F.
    pub l3: f64,
    /// AB = c.
    pub c: f64,
}

impl PantographGeometry {
    /// p0 = δ − γ and p1 = τ (Eq. 3.62-3.63) on any dual-number type.
    pub fn dependent_parameters<D: DualNum<Primitive = f64> + Copy>(&self, q_v: D, q_h: D) -> (D, D) {
        let (c, l) = (self.c, self.l1);
        let k2 = q_v * q_v + q_h * q_h;
        let k = k2.sqrt();
        let p0 = ((k2 + c * c - l * l) / (k * (2.0 * c))).acos() - (q_v / k).asin();
        let p1 = ((-k2 + c * c + l * l) / (2.0 * l * c)).acos();
        (p0, p1)
    }

    /// True when the triangle A-B-D closes: |c − l| < k < c + l.
    pub fn closes(&self, q_v: f64, q_h: f64) -> bool {
        let k = q_v.hypot(q_h);
        k > (self.c - self.l1).abs() && k < self.c + self.l1
    }

    /// Points of the linkage in the leg plane for (q_v, q_h): A, B, C, D, E, F.
    pub fn points(&self, q_v: f64, q_h: f64) -> [Vector2<f64>; 6] {
        let (p0, _) = self.dependent_parameters(q_v, q_h);
        let a = Vector2::new(0.0, q_v);
        let d = Vector2::new(q_h, 0.0);
        let u0 = Vector2::new(p0.cos(), p0.sin());
        let b = a + u0 * self.c;
        let c = a + u0 * self.l0;
        let e = c + (d - b);
        let w = (d - b) / self.l1;
        let f = c + w * self.l3;
        [a, b, c, d, e, f]
    }

    /// Foot position F in the leg plane (x radial, z up, origin C*).
    pub fn foot(&self, q_v: f64, q_h: f64) -> Vector2<f64> {
        self.points(q_v, q_h)[5]
    }
}

impl DependentFunction for PantographGeometry {
    fn input_count(&self) -> usize {
        2
    }
    fn output_count(&self) -> usize {
        2
    }
    fn eval(&self, x: &[Jet], p: &mut [Jet]) {
        let (p0, p1) = self.dependent_parameters(x[0], x[1]);
        p[0] = p0;
        p[1] = p1;
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use approx::assert_relative_eq;

    const AMRU5: PantographGeometry = PantographGeometry { l0: 0.28, l1: 0.07, l2: 0.24, l3: 0.492, c: 0.04 };

    #[test]
    fn linkage_closes_with_the_lengths_of_table_2_1() {
        for &(qv, qh) in &[(0.04, 0.005), (0.06, 0.04), (0.075, 0.055), (0.05, 0.02)] {
            let [a, b, c, d, e, _] = AMRU5.points(qv, qh);
            assert_relative_eq!((b - a).norm(), AMRU5.c, epsilon = 1e-12);
            assert_relative_eq!((c - a).norm(), AMRU5.l0, epsilon = 1e-12);
            assert_relative_eq!((d - b).norm(), AMRU5.l1, epsilon = 1e-12);
            assert_relative_eq!((e - d).norm(), AMRU5.l2, epsilon = 1e-12);
            assert_relative_eq!((e - c).norm(), AMRU5.l1, epsilon = 1e-12);
            // p1 is the angle between link 0 (B→A) and link 1 (B→D).
            let (_, p1) = AMRU5.dependent_parameters(qv, qh);
            assert_relative_eq!(((a - b).dot(&(d - b)) / (AMRU5.c * AMRU5.l1)).acos(), p1, epsilon = 1e-12);
        }
    }

    /// x_foot ≈ 7 q_h and z_foot ≈ −6 q_v (Eq. B.1-B.2); exactly F = A + 7 (D − A) + 0.002 w.
    #[test]
    fn foot_follows_the_amplification_ratios() {
        for &(qv, qh) in &[(0.04, 0.005), (0.06, 0.04), (0.075, 0.055)] {
            let [a, b, _, d, _, f] = AMRU5.points(qv, qh);
            let w = (d - b) / AMRU5.l1;
            assert_relative_eq!(f, a + (d - a) * 7.0 + w * (AMRU5.l3 - 7.0 * AMRU5.l1), epsilon = 1e-12);
            assert!((f.x - 7.0 * qh).abs() < 2.1e-3, "x_foot {} vs 7 q_h {}", f.x, 7.0 * qh);
            assert!((f.y + 6.0 * qv).abs() < 2.1e-3, "z_foot {} vs -6 q_v {}", f.y, -6.0 * qv);
        }
    }
}
