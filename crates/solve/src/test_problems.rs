//! Least-squares problems with known answers for the solvers' unit tests: the MINPACK test set
//! (Moré, Garbow, Hillstrom, "Testing unconstrained optimization software", ACM TOMS 7, 1981;
//! the numbering is theirs), a linear model, and a sphere.

use crate::residuals::Residuals;

/// Writes the residuals at x.
type ResidualFn = dyn Fn(&[f64], &mut Vec<f64>) + Sync;

/// A residual function over a box.
pub struct TestProblem {
    /// Lower bounds.
    pub lo: Vec<f64>,
    /// Upper bounds.
    pub hi: Vec<f64>,
    /// The residuals.
    pub f: Box<ResidualFn>,
}

impl TestProblem {
    /// `f` over the box [lo, hi].
    pub fn new(
        lo: Vec<f64>,
        hi: Vec<f64>,
        f: impl Fn(&[f64], &mut Vec<f64>) + Sync + 'static,
    ) -> TestProblem {
        TestProblem {
            lo,
            hi,
            f: Box::new(f),
        }
    }

    /// The same residuals over another box.
    pub fn with_box(mut self, lo: Vec<f64>, hi: Vec<f64>) -> TestProblem {
        self.lo = lo;
        self.hi = hi;
        self
    }
}

impl Residuals for TestProblem {
    fn dim(&self) -> usize {
        self.lo.len()
    }

    fn bounds(&self) -> (&[f64], &[f64]) {
        (&self.lo, &self.hi)
    }

    fn residuals_at(&self, x: &[f64], out: &mut Vec<f64>) {
        out.clear();
        (self.f)(x, out);
    }
}

fn unbounded(n: usize) -> (Vec<f64>, Vec<f64>) {
    (vec![f64::NEG_INFINITY; n], vec![f64::INFINITY; n])
}

/// #1 Rosenbrock: r = (10(x₂ − x₁²), 1 − x₁); start (−1.2, 1), minimum 0 at (1, 1).
pub fn rosenbrock() -> TestProblem {
    let (lo, hi) = unbounded(2);
    TestProblem::new(lo, hi, |x, r| {
        r.push(10.0 * (x[1] - x[0] * x[0]));
        r.push(1.0 - x[0]);
    })
}

/// The angle θ of the helical valley, in turns.
fn helix_theta(x1: f64, x2: f64) -> f64 {
    let t = (x2 / x1).atan() / (2.0 * std::f64::consts::PI);
    if x1 < 0.0 {
        t + 0.5
    } else {
        t
    }
}

/// #7 Helical valley: r = (10(x₃ − 10θ), 10(√(x₁² + x₂²) − 1), x₃); start (−1, 0, 0), minimum 0
/// at (1, 0, 0).
pub fn helical_valley() -> TestProblem {
    let (lo, hi) = unbounded(3);
    TestProblem::new(lo, hi, |x, r| {
        r.push(10.0 * (x[2] - 10.0 * helix_theta(x[0], x[1])));
        r.push(10.0 * ((x[0] * x[0] + x[1] * x[1]).sqrt() - 1.0));
        r.push(x[2]);
    })
}

/// #13 Powell singular: the Jacobian is singular at the minimum 0 at the origin; start
/// (3, −1, 0, 1).
pub fn powell_singular() -> TestProblem {
    let (lo, hi) = unbounded(4);
    TestProblem::new(lo, hi, |x, r| {
        r.push(x[0] + 10.0 * x[1]);
        r.push(5f64.sqrt() * (x[2] - x[3]));
        r.push((x[1] - 2.0 * x[2]).powi(2));
        r.push(10f64.sqrt() * (x[0] - x[3]).powi(2));
    })
}

/// #8 Bard: 15 data points, a nonzero-residual minimum SSR 8.21487e-3 at (0.0824106, 1.13304,
/// 2.34370); start (1, 1, 1).
pub fn bard() -> TestProblem {
    const Y: [f64; 15] = [
        0.14, 0.18, 0.22, 0.25, 0.29, 0.32, 0.35, 0.39, 0.37, 0.58, 0.73, 0.96, 1.34, 2.10, 4.39,
    ];
    let (lo, hi) = unbounded(3);
    TestProblem::new(lo, hi, |x, r| {
        for (i, y) in Y.iter().enumerate() {
            let u = (i + 1) as f64;
            let v = 16.0 - u;
            let w = u.min(v);
            r.push(y - (x[0] + u / (x[1] * v + x[2] * w)));
        }
    })
}

/// #15 Kowalik–Osborne: 11 data points, minimum SSR 3.07505e-4 at (0.192807, 0.191282,
/// 0.123056, 0.136062); start (0.25, 0.39, 0.415, 0.39).
pub fn kowalik_osborne() -> TestProblem {
    const Y: [f64; 11] = [
        0.1957, 0.1947, 0.1735, 0.1600, 0.0844, 0.0627, 0.0456, 0.0342, 0.0323, 0.0235, 0.0246,
    ];
    const U: [f64; 11] = [
        4.0, 2.0, 1.0, 0.5, 0.25, 0.167, 0.125, 0.1, 0.0833, 0.0714, 0.0625,
    ];
    let (lo, hi) = unbounded(4);
    TestProblem::new(lo, hi, |x, r| {
        for (y, u) in Y.iter().zip(U) {
            r.push(y - x[0] * (u * u + u * x[1]) / (u * u + u * x[2] + x[3]));
        }
    })
}

/// The n × n Hilbert matrix H_ij = 1/(i + j + 1): condition number about 1.5e10 for n = 8,
/// so Hᵀ H (about 1e20) is not even numerically positive definite.
pub fn hilbert(n: usize) -> Vec<Vec<f64>> {
    (0..n)
        .map(|i| (0..n).map(|j| 1.0 / (i + j + 1) as f64).collect())
        .collect()
}

/// A linear model r = A x − b over a box.
pub fn linear(a: Vec<Vec<f64>>, b: Vec<f64>, lo: Vec<f64>, hi: Vec<f64>) -> TestProblem {
    TestProblem::new(lo, hi, move |x, r| {
        for (row, bi) in a.iter().zip(&b) {
            r.push(row.iter().zip(x).map(|(u, v)| u * v).sum::<f64>() - bi);
        }
    })
}

/// The sphere ‖x − c‖² over the box [lo, hi].
pub fn sphere(c: Vec<f64>, lo: Vec<f64>, hi: Vec<f64>) -> TestProblem {
    TestProblem::new(lo, hi, move |x, r| {
        r.extend(x.iter().zip(&c).map(|(u, v)| u - v));
    })
}
