//! Gauss–Legendre quadrature in double precision, for the integrals the core precomputes
//! (the local-integral table, the external diffuse Fresnel reflectance; `docs/physics.md`
//! §15).
//!
//! The nodes are computed at construction by Newton's method on the Legendre polynomial
//! P_N (Golub & Welsch would also do; Newton is simpler and exact to rounding for N ≤ 64), so
//! there is no table of constants to mistype.

use crate::math;

/// An N-point Gauss–Legendre rule on [−1, 1]; exact for polynomials of degree 2N − 1.
#[derive(Clone, Debug)]
pub struct GaussLegendre<const N: usize> {
    nodes: [f64; N],
    weights: [f64; N],
}

impl<const N: usize> Default for GaussLegendre<N> {
    fn default() -> Self {
        Self::new()
    }
}

impl<const N: usize> GaussLegendre<N> {
    /// Computes the nodes and weights.
    pub fn new() -> Self {
        let mut nodes = [0.0; N];
        let mut weights = [0.0; N];
        let n = N as f64;
        for i in 0..N {
            // Tricomi's initial guess for the i-th root, then Newton iterations.
            let mut x = math::cos64(core::f64::consts::PI * (i as f64 + 0.75) / (n + 0.5));
            let mut derivative = 1.0;
            for _ in 0..100 {
                let (p, dp) = legendre(N, x);
                derivative = dp;
                let dx = p / dp;
                x -= dx;
                if dx.abs() < 1e-16 {
                    break;
                }
            }
            let (_, dp) = legendre(N, x);
            if dp.is_finite() {
                derivative = dp;
            }
            nodes[i] = x;
            weights[i] = 2.0 / ((1.0 - x * x) * derivative * derivative);
        }
        GaussLegendre { nodes, weights }
    }

    /// ∫_a^b f(x) dx.
    pub fn integrate(&self, a: f64, b: f64, mut f: impl FnMut(f64) -> f64) -> f64 {
        let half = 0.5 * (b - a);
        let mid = 0.5 * (a + b);
        let mut sum = 0.0;
        for i in 0..N {
            sum += self.weights[i] * f(mid + half * self.nodes[i]);
        }
        sum * half
    }

    /// The rule's nodes and weights mapped to [a, b], as (x_i, w_i) with
    /// Σ w_i f(x_i) = [`GaussLegendre::integrate`]`(a, b, f)` up to rounding: for integral
    /// equations, whose unknown is kept at the nodes.
    pub fn points(&self, a: f64, b: f64) -> impl Iterator<Item = (f64, f64)> + '_ {
        let half = 0.5 * (b - a);
        let mid = 0.5 * (a + b);
        self.nodes
            .iter()
            .zip(&self.weights)
            .map(move |(&x, &w)| (mid + half * x, w * half))
    }

    /// (∫_a^b f₀ dx, ∫_a^b f₁ dx) for f(x) = (f₀(x), f₁(x)), from one evaluation of f per node
    /// (for two integrands that share an expensive factor). Each component is summed as
    /// [`GaussLegendre::integrate`] would, so it gets the same bits.
    pub fn integrate_pair(
        &self,
        a: f64,
        b: f64,
        mut f: impl FnMut(f64) -> (f64, f64),
    ) -> (f64, f64) {
        let half = 0.5 * (b - a);
        let mid = 0.5 * (a + b);
        let mut sum = (0.0, 0.0);
        for i in 0..N {
            let (f0, f1) = f(mid + half * self.nodes[i]);
            sum.0 += self.weights[i] * f0;
            sum.1 += self.weights[i] * f1;
        }
        (sum.0 * half, sum.1 * half)
    }
}

/// P_n(x) and P_n′(x) by the three-term recurrence.
fn legendre(n: usize, x: f64) -> (f64, f64) {
    let (mut p0, mut p1) = (1.0, x);
    for k in 2..=n {
        let k = k as f64;
        let p2 = ((2.0 * k - 1.0) * x * p1 - (k - 1.0) * p0) / k;
        p0 = p1;
        p1 = p2;
    }
    let dp = n as f64 * (x * p1 - p0) / (x * x - 1.0);
    (p1, dp)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn weights_sum_to_two_and_polynomials_are_exact() {
        let rule = GaussLegendre::<16>::new();
        let total: f64 = rule.weights.iter().sum();
        assert!((total - 2.0).abs() < 1e-14);
        // Degree 31 is integrated exactly: ∫_0^1 x^31 dx = 1/32.
        let got = rule.integrate(0.0, 1.0, |x| libm::pow(x, 31.0));
        assert!((got - 1.0 / 32.0).abs() < 1e-15, "{got}");
    }

    #[test]
    fn pair_equals_two_single_integrals_bit_for_bit() {
        let rule = GaussLegendre::<32>::new();
        let (a, b) = (0.3, 2.7);
        let (p, q) = rule.integrate_pair(a, b, |x| (math::exp64(-x), x * x * math::cos64(x)));
        assert_eq!(p, rule.integrate(a, b, |x| math::exp64(-x)));
        assert_eq!(q, rule.integrate(a, b, |x| x * x * math::cos64(x)));
    }

    #[test]
    fn points_reproduce_the_integral() {
        let rule = GaussLegendre::<12>::new();
        let (a, b) = (0.5, 2.0);
        let sum: f64 = rule.points(a, b).map(|(x, w)| w * math::exp64(-x)).sum();
        let want = math::exp64(-0.5) - math::exp64(-2.0);
        assert!((sum - want).abs() < 1e-14, "{sum} vs {want}");
        assert!(rule.points(a, b).all(|(x, w)| x > a && x < b && w > 0.0));
    }

    #[test]
    fn smooth_integral_converges() {
        let rule = GaussLegendre::<24>::new();
        let got = rule.integrate(0.0, 3.0, math::exp64);
        let want = math::exp64(3.0) - 1.0;
        assert!((got - want).abs() / want < 1e-14, "{got} vs {want}");
    }
}
