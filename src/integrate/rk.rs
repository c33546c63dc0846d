//! Explicit Runge-Kutta methods as Butcher tableaux, run by one generic stepper on the
//! first-order system (x' = v, v' = a(x, v)).
//!
//! References: Hairer, Nørsett & Wanner, *Solving ODEs I*, §II.1 (tableaux of the explicit
//! midpoint rule and of the classic fourth-order method of Kutta, 1901).

use super::{ensure_len, StepStats, Stepper};
use crate::error::Result;
use crate::model::{State, System, Vec3};

/// An explicit Butcher tableau: `a` strictly lower triangular, weights `b`, nodes `c`.
#[derive(Debug, Clone, PartialEq)]
pub struct Tableau {
    /// CLI name.
    pub name: &'static str,
    /// Classical order.
    pub order: u32,
    /// Stage coefficients, `a[i][j]` for `j < i`.
    pub a: Vec<Vec<f64>>,
    /// Weights.
    pub b: Vec<f64>,
    /// Nodes (unused by autonomous systems, kept for completeness and checks).
    pub c: Vec<f64>,
}

impl Tableau {
    /// Explicit midpoint rule (RK2), order 2.
    pub fn rk2() -> Self {
        Tableau {
            name: "rk2",
            order: 2,
            a: vec![vec![], vec![0.5]],
            b: vec![0.0, 1.0],
            c: vec![0.0, 0.5],
        }
    }
    /// The classic fourth-order Runge-Kutta method.
    pub fn rk4() -> Self {
        Tableau {
            name: "rk4",
            order: 4,
            a: vec![vec![], vec![0.5], vec![0.0, 0.5], vec![0.0, 0.0, 1.0]],
            b: vec![1.0 / 6.0, 1.0 / 3.0, 1.0 / 3.0, 1.0 / 6.0],
            c: vec![0.0, 0.5, 0.5, 1.0],
        }
    }
    /// Number of stages.
    pub fn stages(&self) -> usize {
        self.b.len()
    }
}

/// Generic explicit Runge-Kutta stepper for a [`Tableau`].
#[derive(Debug)]
pub struct RungeKutta {
    tab: Tableau,
    kx: Vec<Vec<Vec3>>,
    kv: Vec<Vec<Vec3>>,
    xs: Vec<Vec3>,
    vs: Vec<Vec3>,
}

impl RungeKutta {
    /// A stepper for `tab`.
    pub fn new(tab: Tableau) -> Self {
        let s = tab.stages();
        RungeKutta {
            tab,
            kx: vec![Vec::new(); s],
            kv: vec![Vec::new(); s],
            xs: Vec::new(),
            vs: Vec::new(),
        }
    }
}

impl Stepper for RungeKutta {
    fn step(&mut self, sys: &System, s: &mut State, h: f64) -> Result<StepStats> {
        let n = s.len();
        ensure_len(&mut self.xs, n);
        ensure_len(&mut self.vs, n);
        let mut dissipated = 0.0;
        for i in 0..self.tab.stages() {
            ensure_len(&mut self.kx[i], n);
            ensure_len(&mut self.kv[i], n);
            self.xs.copy_from_slice(&s.x);
            self.vs.copy_from_slice(&s.v);
            for (j, &aij) in self.tab.a[i].iter().enumerate() {
                if aij != 0.0 {
                    for p in 0..n {
                        self.xs[p] += self.kx[j][p] * (h * aij);
                        self.vs[p] += self.kv[j][p] * (h * aij);
                    }
                }
            }
            self.kx[i].copy_from_slice(&self.vs);
            let power = sys.accelerations(&self.xs, &self.vs, &mut self.kv[i]);
            dissipated += h * self.tab.b[i] * power;
        }
        for (i, &bi) in self.tab.b.iter().enumerate() {
            if bi != 0.0 {
                for p in 0..n {
                    s.x[p] += self.kx[i][p] * (h * bi);
                    s.v[p] += self.kv[i][p] * (h * bi);
                }
            }
        }
        s.t += h;
        Ok(StepStats {
            force_evals: self.tab.stages() as u64,
            dissipated,
            ..StepStats::default()
        })
    }
}
