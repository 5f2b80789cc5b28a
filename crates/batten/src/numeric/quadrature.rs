/// Gauss–Legendre quadrature rule with `n` nodes, exact for polynomials of degree `2n − 1`.
///
/// Nodes and weights are computed once (Newton's method on the Legendre polynomial) and the
/// rule is reused for every span, so integration allocates nothing per evaluation.
#[derive(Clone, Debug)]
pub struct GaussLegendre {
    nodes: Vec<f64>,
    weights: Vec<f64>,
}

impl GaussLegendre {
    /// Default node count per knot span for arc length and energies: ample for the
    /// piecewise-polynomial integrands of splines up to degree five (see docs/algorithms/README.md
    /// §0.5).
    pub const DEFAULT_NODES: usize = 16;

    /// The rule with `n ≥ 1` nodes on [−1, 1].
    pub fn new(n: usize) -> GaussLegendre {
        let n = n.max(1);
        let mut nodes = vec![0.0; n];
        let mut weights = vec![0.0; n];
        let m = n.div_ceil(2);
        for i in 0..m {
            // Initial guess (Tricomi), then Newton.
            let mut x = (std::f64::consts::PI * (i as f64 + 0.75) / (n as f64 + 0.5)).cos();
            let mut dp = 1.0;
            for _ in 0..100 {
                let (p, d) = legendre(n, x);
                dp = d;
                let dx = p / d;
                x -= dx;
                if dx.abs() < 1e-16 {
                    break;
                }
            }
            let (_, d) = legendre(n, x);
            dp = if d != 0.0 { d } else { dp };
            let w = 2.0 / ((1.0 - x * x) * dp * dp);
            nodes[i] = -x;
            nodes[n - 1 - i] = x;
            weights[i] = w;
            weights[n - 1 - i] = w;
        }
        GaussLegendre { nodes, weights }
    }

    /// The nodes on [−1, 1], increasing.
    pub fn nodes(&self) -> &[f64] {
        &self.nodes
    }

    /// The weights, matching [`GaussLegendre::nodes`].
    pub fn weights(&self) -> &[f64] {
        &self.weights
    }

    /// ∫_a^b f(t) dt.
    pub fn integrate(&self, a: f64, b: f64, mut f: impl FnMut(f64) -> f64) -> f64 {
        let half = 0.5 * (b - a);
        let mid = 0.5 * (a + b);
        let mut s = 0.0;
        for (x, w) in self.nodes.iter().zip(&self.weights) {
            s += w * f(mid + half * x);
        }
        s * half
    }
}

impl Default for GaussLegendre {
    fn default() -> GaussLegendre {
        GaussLegendre::new(GaussLegendre::DEFAULT_NODES)
    }
}

/// P_n(x) and P_n'(x) by the three-term recurrence.
fn legendre(n: usize, x: f64) -> (f64, f64) {
    let (mut p0, mut p1) = (1.0, x);
    if n == 0 {
        return (1.0, 0.0);
    }
    for k in 2..=n {
        let k = k as f64;
        let p2 = ((2.0 * k - 1.0) * x * p1 - (k - 1.0) * p0) / k;
        p0 = p1;
        p1 = p2;
    }
    let d = n as f64 * (x * p1 - p0) / (x * x - 1.0);
    (p1, d)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn exact_for_polynomials() {
        for n in 1..12 {
            let g = GaussLegendre::new(n);
            let deg = 2 * n - 1;
            let got = g.integrate(0.0, 2.0, |t| t.powi(deg as i32));
            let exact = 2f64.powi(deg as i32 + 1) / (deg as f64 + 1.0);
            assert!((got - exact).abs() < 1e-12 * exact, "n={n}");
            let wsum: f64 = g.weights().iter().sum();
            assert!((wsum - 2.0).abs() < 1e-13);
        }
    }

    #[test]
    fn smooth_integrand() {
        let g = GaussLegendre::default();
        let got = g.integrate(0.0, std::f64::consts::PI, f64::sin);
        assert!((got - 2.0).abs() < 1e-14);
    }
}
