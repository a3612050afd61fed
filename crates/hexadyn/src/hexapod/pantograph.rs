//! The pantograph leg mechanism (thesis Section 3.4.1, Fig. 3.8, NOTES.md): dependent
//! parameters p0, p1 of Eq. 3.53-3.63 and the planar linkage A-B-C, B-D, D-E, C-E-F.
//!
//! Leg-plane coordinates (x radial outward, z up) have their origin at the crossing point C*.
//! A = (0, q_v) is driven by the vertical nut, D = (q_h, 0) by the horizontal one; in triangle
//! A-B-D the sides are c = AB, l = BD and k = AD (the triangle "klc" of Eq. 3.57-3.63).

use nalgebra::Vector2;

use super::joints::{JointKind, JointNameError, LegJoints};
use crate::mbs::{DependentFunction, DependentValue, DualNum, Jet};

/// The three actuated joints of a pantograph leg (Eq. 3.51): q_r the rotation of the leg
/// chassis about the vertical axis, q_v the vertical and q_h the horizontal ball-screw nut
/// positions. Their symbols name the joint tables of the pantograph robot description
/// (`[controller.q_r]`, `[friction.q_v]`, ...); the results columns use the robot's
/// [`LegJoints`], which on AMRU5 carries the same names.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub enum PantographJoint {
    /// q_r, rad (joint torques in Nm).
    Rotation,
    /// q_v, m (joint "torques" are forces in N).
    Vertical,
    /// q_h, m (joint "torques" are forces in N).
    Horizontal,
}

impl PantographJoint {
    /// The three joints in the thesis order (q_r, q_v, q_h).
    pub const ALL: [PantographJoint; 3] = [PantographJoint::Rotation, PantographJoint::Vertical, PantographJoint::Horizontal];

    /// Thesis symbol: `q_r`, `q_v` or `q_h` (also the description's table names and the
    /// default joint names of a pantograph robot).
    pub fn symbol(self) -> &'static str {
        match self {
            PantographJoint::Rotation => "q_r",
            PantographJoint::Vertical => "q_v",
            PantographJoint::Horizontal => "q_h",
        }
    }

    /// Revolute for q_r (radians and Nm), prismatic for the nuts (metres and N).
    pub fn kind(self) -> JointKind {
        match self {
            PantographJoint::Rotation => JointKind::Revolute,
            PantographJoint::Vertical | PantographJoint::Horizontal => JointKind::Prismatic,
        }
    }

    /// True for q_r (radians and Nm), false for the translational joints (metres and N).
    pub fn is_rotational(self) -> bool {
        self.kind() == JointKind::Revolute
    }

    /// The pantograph's joint vocabulary with the given names (in the order q_r, q_v, q_h).
    pub fn leg_joints(names: [String; 3]) -> Result<LegJoints, JointNameError> {
        LegJoints::new(names, PantographJoint::ALL.map(PantographJoint::kind))
    }
}

impl std::fmt::Display for PantographJoint {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.write_str(self.symbol())
    }
}

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

    /// (sin p0, cos p0) of Eq. 3.62 without the angle (see [`p0_sin_cos`]): what the foot
    /// needs, at no arc cosine, arc sine, sine or cosine.
    pub fn p0_sin_cos(&self, q_v: f64, q_h: f64) -> (f64, f64) {
        let (c, l) = (self.c, self.l1);
        let k2 = q_v * q_v + q_h * q_h;
        let k = k2.sqrt();
        p0_sin_cos((k2 + c * c - l * l) / (k * (2.0 * c)), q_v / k)
    }

    /// True when the triangle A-B-D closes: |c − l| < k < c + l.
    pub fn closes(&self, q_v: f64, q_h: f64) -> bool {
        let k = q_v.hypot(q_h);
        k > (self.c - self.l1).abs() && k < self.c + self.l1
    }

    /// Points of the linkage in the leg plane for (q_v, q_h): A, B, C, D, E, F.
    pub fn points(&self, q_v: f64, q_h: f64) -> [Vector2<f64>; 6] {
        let (sin_p0, cos_p0) = self.p0_sin_cos(q_v, q_h);
        let a = Vector2::new(0.0, q_v);
        let d = Vector2::new(q_h, 0.0);
        let u0 = Vector2::new(cos_p0, sin_p0);
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

    /// [`PantographGeometry::dependent_parameters`] differentiated by hand through k = |AD|:
    /// p1 = acos(u1(k²)), p0 = acos(u0(k)) − asin(q_v / k); their sines and cosines from the
    /// same arguments, (sin p1, cos p1) = (√(1 − u1²), u1) and, with a = acos(u0), b = asin(w),
    /// sin p0 = sin a cos b − cos a sin b, cos p0 = cos a cos b + sin a sin b.
    fn eval_closed_form(&self, x: &[f64], xd: &[f64], out: &mut [DependentValue]) -> bool {
        let (c, l) = (self.c, self.l1);
        let (v, h, vd, hd) = (x[0], x[1], xd[0], xd[1]);
        let k2 = Scalar { value: v * v + h * h, gradient: [2.0 * v, 2.0 * h], rate: 2.0 * (v * vd + h * hd), bias: 2.0 * (vd * vd + hd * hd) };
        let k = k2.then(k2.value.sqrt(), 0.5 / k2.value.sqrt(), -0.25 / (k2.value * k2.value.sqrt()));
        // u1 = (c² + l² − k²) / (2 l c), linear in k².
        let u1 = k2.then((c * c + l * l - k2.value) / (2.0 * l * c), -1.0 / (2.0 * l * c), 0.0);
        // u0 = (k² + c² − l²) / (2 c k) = k / 2c + a / k.
        let a = (c * c - l * l) / (2.0 * c);
        let u0 = k.then(k.value / (2.0 * c) + a / k.value, 1.0 / (2.0 * c) - a / (k.value * k.value), 2.0 * a / k.value.powi(3));
        // w = q_v / k, a product of q_v and 1 / k.
        let inv_k = k.then(1.0 / k.value, -1.0 / (k.value * k.value), 2.0 / k.value.powi(3));
        let w = Scalar {
            value: v * inv_k.value,
            gradient: [inv_k.value + v * inv_k.gradient[0], v * inv_k.gradient[1]],
            rate: vd * inv_k.value + v * inv_k.rate,
            bias: 2.0 * vd * inv_k.rate + v * inv_k.bias,
        };
        let p0 = u0.acos().minus(&w.asin());
        let p1 = u1.acos();
        let sin_cos_p0 = p0_sin_cos(u0.value, w.value);
        let sin_cos_p1 = ((1.0 - u1.value * u1.value).sqrt(), u1.value);
        for (o, (p, sin_cos)) in out.iter_mut().zip([(p0, sin_cos_p0), (p1, sin_cos_p1)]) {
            o.value = p.value;
            o.rate = p.rate;
            o.bias = p.bias;
            o.gradient.copy_from_slice(&p.gradient);
            o.sin_cos = Some(sin_cos);
        }
        true
    }
}

/// (sin p0, cos p0) for p0 = a − b with a = acos(u0), b = asin(w) (Eq. 3.62: u0 = cos δ,
/// w = q_v / k = sin γ): sin p0 = sin a cos b − cos a sin b, cos p0 = cos a cos b + sin a sin b,
/// sin a = √(1 − u0²), cos b = √(1 − w²).
fn p0_sin_cos(u0: f64, w: f64) -> (f64, f64) {
    let (sin_a, cos_b) = ((1.0 - u0 * u0).sqrt(), (1.0 - w * w).sqrt());
    (sin_a * cos_b - u0 * w, u0 * cos_b + sin_a * w)
}

/// A scalar function of (q_v, q_h) with its gradient, its rate along (q̇_v, q̇_h) and the
/// convective part of its second derivative, ẋᵀ H ẋ.
#[derive(Clone, Copy, Debug)]
struct Scalar {
    value: f64,
    gradient: [f64; 2],
    rate: f64,
    bias: f64,
}

impl Scalar {
    /// f(self) from f, f' and f'' at self.value (chain rule: the bias is f'' ṡ² + f' s̈_bias).
    fn then(&self, value: f64, d1: f64, d2: f64) -> Scalar {
        Scalar { value, gradient: self.gradient.map(|g| d1 * g), rate: d1 * self.rate, bias: d2 * self.rate * self.rate + d1 * self.bias }
    }
    fn acos(&self) -> Scalar {
        let s = 1.0 - self.value * self.value;
        self.then(self.value.acos(), -1.0 / s.sqrt(), -self.value / (s * s.sqrt()))
    }
    fn asin(&self) -> Scalar {
        let s = 1.0 - self.value * self.value;
        self.then(self.value.asin(), 1.0 / s.sqrt(), self.value / (s * s.sqrt()))
    }
    fn minus(&self, other: &Scalar) -> Scalar {
        Scalar { value: self.value - other.value, gradient: [self.gradient[0] - other.gradient[0], self.gradient[1] - other.gradient[1]], rate: self.rate - other.rate, bias: self.bias - other.bias }
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

    /// The closed-form derivatives are those of the jets of `eval` (the definition), over the
    /// joint ranges and at any rates, and its sines and cosines those of the values.
    #[test]
    fn closed_form_derivatives_match_the_jets() {
        let fresh = || vec![DependentValue { gradient: vec![0.0; 2], ..Default::default() }; 2];
        for &(qv, qh, vd, hd) in &[(0.04, 0.005, 1e-3, -2e-3), (0.06, 0.04, -0.01, 0.003), (0.075, 0.055, 0.02, 0.02), (0.05, 0.02, 0.0, 0.0)] {
            let (mut closed, mut jets) = (fresh(), fresh());
            assert!(AMRU5.eval_closed_form(&[qv, qh], &[vd, hd], &mut closed));
            crate::mbs::evaluate_jets(&AMRU5, &[qv, qh], &[vd, hd], &mut jets, &mut Vec::new());
            for (c, j) in closed.iter().zip(&jets) {
                assert_relative_eq!(c.value, j.value, epsilon = 1e-14);
                assert_relative_eq!(c.rate, j.rate, epsilon = 1e-14, max_relative = 1e-12);
                assert_relative_eq!(c.bias, j.bias, epsilon = 1e-14, max_relative = 1e-12);
                for (cg, jg) in c.gradient.iter().zip(&j.gradient) {
                    assert_relative_eq!(*cg, *jg, max_relative = 1e-12);
                }
                let (sin, cos) = c.sin_cos.expect("the closed form gives them");
                assert_relative_eq!(sin, c.value.sin(), epsilon = 1e-15);
                assert_relative_eq!(cos, c.value.cos(), epsilon = 1e-15);
                assert_eq!(j.sin_cos, None);
            }
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
