//! Dormand–Prince 8(5,3) with 7th-order dense output: the adaptive reference solver.
//!
//! Method and coefficients: Hairer, Nørsett & Wanner, *Solving Ordinary Differential
//! Equations I* (2nd ed., 1993), §II.10, and Hairer's Fortran code DOP853 (the same constants
//! are used by SciPy's `DOP853`). The error estimate combines the 5th- and 3rd-order embedded
//! estimates as in DOP853; step control uses the 1/8 exponent, safety 0.9 and factors in
//! [0.2, 10]. Dense output uses three extra stages (a degree-7 interpolant).

// Coefficients are typed as published (30 digits); f64 rounds them once, correctly.
#![allow(clippy::excessive_precision)]

/// One right-hand side evaluation y' = f(t, y).
pub type Rhs<'a> = dyn FnMut(f64, &[f64], &mut [f64]) + 'a;

const N_STAGES: usize = 12;
const N_EXT: usize = 16;

const C: [f64; N_EXT] = [
    0.0,
    0.526001519587677318785587544488e-01,
    0.789002279381515978178381316732e-01,
    0.118350341907227396726757197510,
    0.281649658092772603273242802490,
    0.333333333333333333333333333333,
    0.25,
    0.307692307692307692307692307692,
    0.651282051282051282051282051282,
    0.6,
    0.857142857142857142857142857142,
    1.0,
    1.0,
    0.1,
    0.2,
    0.777777777777777777777777777778,
];

/// Nonzero stage coefficients a[i][j] as (i, j, value).
#[rustfmt::skip]
const A: &[(usize, usize, f64)] = &[
    (1, 0, 5.26001519587677318785587544488e-2),
    (2, 0, 1.97250569845378994544595329183e-2),
    (2, 1, 5.91751709536136983633785987549e-2),
    (3, 0, 2.95875854768068491816892993775e-2),
    (3, 2, 8.87627564304205475450678981324e-2),
    (4, 0, 2.41365134159266685502369798665e-1),
    (4, 2, -8.84549479328286085344864962717e-1),
    (4, 3, 9.24834003261792003115737966543e-1),
    (5, 0, 3.7037037037037037037037037037e-2),
    (5, 3, 1.70828608729473871279604482173e-1),
    (5, 4, 1.25467687566822425016691814123e-1),
    (6, 0, 3.7109375e-2),
    (6, 3, 1.70252211019544039314978060272e-1),
    (6, 4, 6.02165389804559606850219397283e-2),
    (6, 5, -1.7578125e-2),
    (7, 0, 3.70920001185047927108779319836e-2),
    (7, 3, 1.70383925712239993810214054705e-1),
    (7, 4, 1.07262030446373284651809199168e-1),
    (7, 5, -1.53194377486244017527936158236e-2),
    (7, 6, 8.27378916381402288758473766002e-3),
    (8, 0, 6.24110958716075717114429577812e-1),
    (8, 3, -3.36089262944694129406857109825),
    (8, 4, -8.68219346841726006818189891453e-1),
    (8, 5, 2.75920996994467083049415600797e1),
    (8, 6, 2.01540675504778934086186788979e1),
    (8, 7, -4.34898841810699588477366255144e1),
    (9, 0, 4.77662536438264365890433908527e-1),
    (9, 3, -2.48811461997166764192642586468),
    (9, 4, -5.90290826836842996371446475743e-1),
    (9, 5, 2.12300514481811942347288949897e1),
    (9, 6, 1.52792336328824235832596922938e1),
    (9, 7, -3.32882109689848629194453265587e1),
    (9, 8, -2.03312017085086261358222928593e-2),
    (10, 0, -9.3714243008598732571704021658e-1),
    (10, 3, 5.18637242884406370830023853209),
    (10, 4, 1.09143734899672957818500254654),
    (10, 5, -8.14978701074692612513997267357),
    (10, 6, -1.85200656599969598641566180701e1),
    (10, 7, 2.27394870993505042818970056734e1),
    (10, 8, 2.49360555267965238987089396762),
    (10, 9, -3.0467644718982195003823669022),
    (11, 0, 2.27331014751653820792359768449),
    (11, 3, -1.05344954667372501984066689879e1),
    (11, 4, -2.00087205822486249909675718444),
    (11, 5, -1.79589318631187989172765950534e1),
    (11, 6, 2.79488845294199600508499808837e1),
    (11, 7, -2.85899827713502369474065508674),
    (11, 8, -8.87285693353062954433549289258),
    (11, 9, 1.23605671757943030647266201528e1),
    (11, 10, 6.43392746015763530355970484046e-1),
    // Row 12 holds the 8th-order weights b.
    (12, 0, 5.42937341165687622380535766363e-2),
    (12, 5, 4.45031289275240888144113950566),
    (12, 6, 1.89151789931450038304281599044),
    (12, 7, -5.8012039600105847814672114227),
    (12, 8, 3.1116436695781989440891606237e-1),
    (12, 9, -1.52160949662516078556178806805e-1),
    (12, 10, 2.01365400804030348374776537501e-1),
    (12, 11, 4.47106157277725905176885569043e-2),
    // Rows 13-15: the extra stages of the dense output.
    (13, 0, 5.61675022830479523392909219681e-2),
    (13, 6, 2.53500210216624811088794765333e-1),
    (13, 7, -2.46239037470802489917441475441e-1),
    (13, 8, -1.24191423263816360469010140626e-1),
    (13, 9, 1.5329179827876569731206322685e-1),
    (13, 10, 8.20105229563468988491666602057e-3),
    (13, 11, 7.56789766054569976138603589584e-3),
    (13, 12, -8.298e-3),
    (14, 0, 3.18346481635021405060768473261e-2),
    (14, 5, 2.83009096723667755288322961402e-2),
    (14, 6, 5.35419883074385676223797384372e-2),
    (14, 7, -5.49237485713909884646569340306e-2),
    (14, 10, -1.08347328697249322858509316994e-4),
    (14, 11, 3.82571090835658412954920192323e-4),
    (14, 12, -3.40465008687404560802977114492e-4),
    (14, 13, 1.41312443674632500278074618366e-1),
    (15, 0, -4.28896301583791923408573538692e-1),
    (15, 5, -4.69762141536116384314449447206),
    (15, 6, 7.68342119606259904184240953878),
    (15, 7, 4.06898981839711007970213554331),
    (15, 8, 3.56727187455281109270669543021e-1),
    (15, 12, -1.39902416515901462129418009734e-3),
    (15, 13, 2.9475147891527723389556272149),
    (15, 14, -9.15095847217987001081870187138),
];

/// b minus the 3rd-order weights (nonzero entries of E3 besides b itself).
const E3_DIFF: [(usize, f64); 3] = [
    (0, 0.244094488188976377952755905512),
    (8, 0.733846688281611857341361741547),
    (11, 0.220588235294117647058823529412e-1),
];

/// The 5th-order error estimator weights.
const E5: [(usize, f64); 8] = [
    (0, 0.1312004499419488073250102996e-1),
    (5, -0.1225156446376204440720569753e1),
    (6, -0.4957589496572501915214079952),
    (7, 0.1664377182454986536961530415e1),
    (8, -0.3503288487499736816886487290),
    (9, 0.3341791187130174790297318841),
    (10, 0.8192320648511571246570742613e-1),
    (11, -0.2235530786388629525884427845e-1),
];

/// Dense-output coefficients for the interpolant's last four terms.
#[rustfmt::skip]
const D: [[f64; N_EXT]; 4] = [
    [-0.84289382761090128651353491142e1, 0.0, 0.0, 0.0, 0.0, 0.56671495351937776962531783590,
     -0.30689499459498916912797304727e1, 0.23846676565120698287728149680e1,
     0.21170345824450282767155149946e1, -0.87139158377797299206789907490,
     0.22404374302607882758541771650e1, 0.63157877876946881815570249290,
     -0.88990336451333310820698117400e-1, 0.18148505520854727256656404962e2,
     -0.91946323924783554000451984436e1, -0.44360363875948939664310572000e1],
    [0.10427508642579134603413151009e2, 0.0, 0.0, 0.0, 0.0, 0.24228349177525818288430175319e3,
     0.16520045171727028198505394887e3, -0.37454675472269020279518312152e3,
     -0.22113666853125306036270938578e2, 0.77334326684722638389603898808e1,
     -0.30674084731089398182061213626e2, -0.93321305264302278729567221706e1,
     0.15697238121770843886131091075e2, -0.31139403219565177677282850411e2,
     -0.93529243588444783865713862664e1, 0.35816841486394083752465898540e2],
    [0.19985053242002433820987653617e2, 0.0, 0.0, 0.0, 0.0, -0.38703730874935176555105901742e3,
     -0.18917813819516756882830838328e3, 0.52780815920542364900561016686e3,
     -0.11573902539959630126141871134e2, 0.68812326946963000169666922661e1,
     -0.10006050966910838403183860980e1, 0.77771377980534432092869265740,
     -0.27782057523535084065932004339e1, -0.60196695231264120758267380846e2,
     0.84320405506677161018159903784e2, 0.11992291136182789328035130030e2],
    [-0.25693933462703749003312586129e2, 0.0, 0.0, 0.0, 0.0, -0.15418974869023643374053993627e3,
     -0.23152937917604549567536039109e3, 0.35763911791061412378285349910e3,
     0.93405324183624310003907691704e2, -0.37458323136451633156875139351e2,
     0.10409964950896230045147246184e3, 0.29840293426660503123344363579e2,
     -0.43533456590011143754432175058e2, 0.96324553959188282948394950600e2,
     -0.39177261675615439165231486172e2, -0.14972683625798562581422125276e3],
];

/// Where each stage's coefficients start in [`A`] (sorted by stage), with the end last.
const ROW_START: [usize; N_EXT + 1] = row_starts();

const fn row_starts() -> [usize; N_EXT + 1] {
    let mut starts = [A.len(); N_EXT + 1];
    let mut s = N_EXT;
    while s > 0 {
        s -= 1;
        let mut k = starts[s + 1];
        while k > 0 && A[k - 1].0 >= s {
            k -= 1;
        }
        starts[s] = k;
    }
    starts
}

/// Stage `s`'s nonzero coefficients a[s][j], in increasing j.
fn row(s: usize) -> &'static [(usize, usize, f64)] {
    &A[ROW_START[s]..ROW_START[s + 1]]
}

/// Elements per block of the stage combinations: a block of the result stays in the first
/// cache level while every term is added to it.
const BLOCK: usize = 512;

/// `out = base + Σ (scale·a) k_j` over the coefficients `terms` (j, a), added term by term in
/// their order (each element sees the same operations as term-by-term passes over the whole
/// vector; done block by block so the block being summed stays in cache).
fn combine(
    out: &mut [f64],
    base: &[f64],
    terms: &[(usize, usize, f64)],
    scale: f64,
    k: &[Vec<f64>],
) {
    let n = out.len();
    let mut lo = 0;
    while lo < n {
        let hi = (lo + BLOCK).min(n);
        let o = &mut out[lo..hi];
        o.copy_from_slice(&base[lo..hi]);
        for &(_, j, a) in terms {
            let ha = scale * a;
            for (x, kj) in o.iter_mut().zip(&k[j][lo..hi]) {
                *x += ha * kj;
            }
        }
        lo = hi;
    }
}

const SAFETY: f64 = 0.9;
const MIN_FACTOR: f64 = 0.2;
const MAX_FACTOR: f64 = 10.0;

/// What the solver did so far.
#[derive(Debug, Clone, Copy, Default, PartialEq, serde::Serialize)]
pub struct Dop853Stats {
    /// Accepted steps.
    pub steps: u64,
    /// Rejected step attempts.
    pub rejected: u64,
    /// Right-hand side evaluations.
    pub evals: u64,
}

/// The adaptive DOP853 solver state: the current point, the last accepted step and its
/// dense output.
#[derive(Debug, Clone)]
pub struct Dop853 {
    rtol: f64,
    atol: f64,
    /// Current time.
    pub t: f64,
    /// Current solution.
    pub y: Vec<f64>,
    /// Start of the last accepted step.
    pub t_old: f64,
    /// Solution at `t_old`.
    pub y_old: Vec<f64>,
    f: Vec<f64>,
    h: f64,
    k: Vec<Vec<f64>>,
    tmp: Vec<f64>,
    y_new: Vec<f64>,
    dense: Vec<Vec<f64>>,
    dense_ready: bool,
    /// Work counters.
    pub stats: Dop853Stats,
}

fn rms(v: impl Iterator<Item = f64>, n: usize) -> f64 {
    (v.map(|x| x * x).sum::<f64>() / n.max(1) as f64).sqrt()
}

impl Dop853 {
    /// A solver for `n` unknowns with relative and absolute tolerances.
    pub fn new(n: usize, rtol: f64, atol: f64) -> Self {
        Dop853 {
            rtol,
            atol,
            t: 0.0,
            y: vec![0.0; n],
            t_old: 0.0,
            y_old: vec![0.0; n],
            f: vec![0.0; n],
            h: 0.0,
            k: vec![vec![0.0; n]; N_EXT],
            tmp: vec![0.0; n],
            y_new: vec![0.0; n],
            dense: vec![vec![0.0; n]; DENSE_ROWS],
            dense_ready: false,
            stats: Dop853Stats::default(),
        }
    }

    fn eval(&mut self, rhs: &mut Rhs<'_>, t: f64, stage: usize) {
        rhs(t, &self.tmp, &mut self.k[stage]);
        self.stats.evals += 1;
    }

    /// (Re)starts at (t0, y0) with a fresh initial step estimate (Hairer's algorithm).
    pub fn start(&mut self, rhs: &mut Rhs<'_>, t0: f64, y0: &[f64], t_bound: f64) {
        self.t = t0;
        self.y.copy_from_slice(y0);
        self.t_old = t0;
        self.y_old.copy_from_slice(y0);
        rhs(t0, &self.y, &mut self.f);
        self.stats.evals += 1;
        self.dense_ready = false;
        let n = self.y.len();
        let scale: Vec<f64> = self
            .y
            .iter()
            .map(|y| self.atol + y.abs() * self.rtol)
            .collect();
        let d0 = rms(self.y.iter().zip(&scale).map(|(y, s)| y / s), n);
        let d1 = rms(self.f.iter().zip(&scale).map(|(f, s)| f / s), n);
        let h0 = if d0 < 1e-5 || d1 < 1e-5 {
            1e-6
        } else {
            0.01 * d0 / d1
        };
        for i in 0..n {
            self.tmp[i] = self.y[i] + h0 * self.f[i];
        }
        let mut f1 = vec![0.0; n];
        rhs(t0 + h0, &self.tmp, &mut f1);
        self.stats.evals += 1;
        let d2 = rms(
            f1.iter()
                .zip(&self.f)
                .zip(&scale)
                .map(|((a, b), s)| (a - b) / s),
            n,
        ) / h0;
        let h1 = if d1 <= 1e-15 && d2 <= 1e-15 {
            (h0 * 1e-3).max(1e-6)
        } else {
            (0.01 / d1.max(d2)).powf(1.0 / 8.0)
        };
        self.h = (100.0 * h0)
            .min(h1)
            .min((t_bound - t0).abs().max(f64::MIN_POSITIVE));
    }

    /// The derivative f(t, y) at the current point (valid after `start`, `step` or `set_y`).
    pub fn derivative(&self) -> &[f64] {
        &self.f
    }

    /// Replaces the current solution (after a projection) keeping the step size.
    pub fn set_y(&mut self, rhs: &mut Rhs<'_>, y: &[f64]) {
        self.y.copy_from_slice(y);
        rhs(self.t, &self.y, &mut self.f);
        self.stats.evals += 1;
        self.dense_ready = false;
    }

    /// One attempt with step `h` from (t, y): fills the stages, `y_new`, and returns the
    /// scaled error norm.
    fn attempt(&mut self, rhs: &mut Rhs<'_>, h: f64) -> f64 {
        let n = self.y.len();
        self.k[0].copy_from_slice(&self.f);
        for (s, &cs) in C.iter().enumerate().take(N_STAGES + 1).skip(1) {
            combine(&mut self.tmp, &self.y, row(s), h, &self.k);
            if s < N_STAGES {
                self.eval(rhs, self.t + cs * h, s);
            } else {
                // Stage 12 is the 8th-order solution; its derivative is K[12].
                self.y_new.copy_from_slice(&self.tmp);
                self.eval(rhs, self.t + h, N_STAGES);
            }
        }
        let (mut e5, mut e3) = (0.0, 0.0);
        let b = row(N_STAGES);
        for i in 0..n {
            let sc = self.atol + self.y[i].abs().max(self.y_new[i].abs()) * self.rtol;
            let mut err5 = 0.0;
            for &(j, w) in &E5 {
                err5 += w * self.k[j][i];
            }
            // err3 = Σ b_j k_j - Σ bhat_j k_j, with b from row 12 of A.
            let mut err3 = 0.0;
            for &(_, j, a) in b {
                err3 += a * self.k[j][i];
            }
            for &(j, w) in &E3_DIFF {
                err3 -= w * self.k[j][i];
            }
            e5 += (err5 / sc).powi(2);
            e3 += (err3 / sc).powi(2);
        }
        let denom = e5 + 0.01 * e3;
        if denom > 0.0 {
            h.abs() * e5 / (denom * n as f64).sqrt()
        } else {
            0.0
        }
    }

    fn accept(&mut self, h: f64) {
        self.t_old = self.t;
        std::mem::swap(&mut self.y_old, &mut self.y);
        self.y.copy_from_slice(&self.y_new);
        self.f.copy_from_slice(&self.k[N_STAGES]);
        self.t += h;
        self.dense_ready = false;
        self.stats.steps += 1;
    }

    /// Takes one accepted adaptive step, never past `t_bound`. Errors when the step size
    /// underflows (the solution is singular or the tolerance is unreachable).
    pub fn step(&mut self, rhs: &mut Rhs<'_>, t_bound: f64) -> Result<(), String> {
        let mut rejected = false;
        loop {
            let room = t_bound - self.t;
            let mut h = self.h.min(room);
            // Avoid a sliver step at the end.
            if room - h < 1e-3 * h {
                h = room;
            }
            if h <= 10.0 * f64::EPSILON * self.t.abs().max(1.0) {
                return Err(format!("step size underflow at t = {}", self.t));
            }
            let err = self.attempt(rhs, h);
            if !err.is_finite() {
                self.stats.rejected += 1;
                self.h = h * MIN_FACTOR;
                rejected = true;
                continue;
            }
            if err < 1.0 {
                let mut factor = if err == 0.0 {
                    MAX_FACTOR
                } else {
                    (SAFETY * err.powf(-1.0 / 8.0)).min(MAX_FACTOR)
                };
                if rejected {
                    factor = factor.min(1.0);
                }
                self.accept(h);
                // Keep the proposal from the full step even if this one was clipped.
                self.h = (h * factor).max(self.h.min(h * factor.max(1.0)));
                return Ok(());
            }
            self.stats.rejected += 1;
            self.h = h * (SAFETY * err.powf(-1.0 / 8.0)).max(MIN_FACTOR);
            rejected = true;
        }
    }

    /// Takes one step of exactly `h` with no error control (for order tests).
    #[cfg(test)]
    pub fn step_fixed(&mut self, rhs: &mut Rhs<'_>, h: f64) {
        self.attempt(rhs, h);
        self.accept(h);
    }

    /// Computes the extra stages of the dense output for the last accepted step.
    pub fn prepare_dense(&mut self, rhs: &mut Rhs<'_>) {
        if self.dense_ready {
            return;
        }
        let n = self.y.len();
        let h = self.t - self.t_old;
        for (s, &cs) in C.iter().enumerate().skip(13) {
            combine(&mut self.tmp, &self.y_old, row(s), h, &self.k);
            rhs(self.t_old + cs * h, &self.tmp, &mut self.k[s]);
            self.stats.evals += 1;
        }
        // The interpolant's nonzero weights, in column order.
        let mut weights = [[(0usize, 0.0f64); N_EXT]; 4];
        let mut counts = [0usize; 4];
        for (r, drow) in D.iter().enumerate() {
            for (j, &d) in drow.iter().enumerate() {
                if d != 0.0 {
                    weights[r][counts[r]] = (j, d);
                    counts[r] += 1;
                }
            }
        }
        for i in 0..n {
            let dy = self.y[i] - self.y_old[i];
            let f_old = self.k[0][i];
            let f_new = self.k[N_STAGES][i];
            self.dense[0][i] = dy;
            self.dense[1][i] = h * f_old - dy;
            self.dense[2][i] = 2.0 * dy - h * (f_new + f_old);
        }
        // Each row is summed stage by stage over whole vectors (unit stride), in the same
        // order per element as a per-element sum: the same bits, several times faster.
        for (r, w) in weights.iter().enumerate() {
            let row = &mut self.dense[3 + r];
            row.fill(0.0);
            for &(j, d) in &w[..counts[r]] {
                for (acc, kj) in row.iter_mut().zip(&self.k[j]) {
                    *acc += d * kj;
                }
            }
            for acc in row.iter_mut() {
                *acc *= h;
            }
        }
        self.dense_ready = true;
    }

    /// The dense output at `t` in [t_old, t] (call [`Dop853::prepare_dense`] first).
    pub fn dense(&self, t: f64, out: &mut [f64]) {
        assert!(self.dense_ready, "prepare_dense before dense");
        if t == self.t {
            out.copy_from_slice(&self.y);
            return;
        }
        let x = (t - self.t_old) / (self.t - self.t_old);
        for (i, o) in out.iter_mut().enumerate() {
            *o = interpolate(|r| self.dense[r][i], x, DENSE_ROWS) + self.y_old[i];
        }
    }

    /// The last accepted step's dense-output rows (valid after [`Dop853::prepare_dense`]):
    /// with `y_old`, they give the interpolant through [`interpolate`].
    pub fn dense_rows(&self) -> &[Vec<f64>] {
        assert!(self.dense_ready, "prepare_dense before dense_rows");
        &self.dense
    }
}

/// Number of dense-output rows (the interpolant's degree).
pub const DENSE_ROWS: usize = 7;

/// The dense-output increment y(t) − y_old at fraction `x` of a step from its rows
/// (`row(r)`, r < `terms`): Hairer's contd8 in the alternating basis x, (1 − x). With
/// `terms` = [`DENSE_ROWS`] it is the 7th-order interpolant; with fewer, its truncation
/// (3 rows: the cubic Hermite interpolant of the step's end values and derivatives).
pub fn interpolate(row: impl Fn(usize) -> f64, x: f64, terms: usize) -> f64 {
    let mut y = 0.0;
    for r in (0..terms).rev() {
        y += row(r);
        // Horner in the alternating basis x, (1 - x): even counts from the top use x.
        if (6 - r) % 2 == 0 {
            y *= x;
        } else {
            y *= 1.0 - x;
        }
    }
    y
}

#[cfg(test)]
mod tests {
    use super::*;

    // Oracle: the harmonic oscillator y'' = -y has the closed form cos t, -sin t.
    fn osc(_t: f64, y: &[f64], d: &mut [f64]) {
        d[0] = y[1];
        d[1] = -y[0];
    }

    // Oracle: the tableau itself. Each stage's row holds exactly that stage's coefficients of
    // `A`, and the rows together hold all of them, in order.
    #[test]
    fn rows_split_the_tableau_by_stage() {
        let mut all = Vec::new();
        for s in 0..N_EXT {
            assert!(row(s).iter().all(|e| e.0 == s), "stage {s}");
            all.extend_from_slice(row(s));
        }
        assert_eq!(all, A);
        assert!(row(0).is_empty() && row(N_STAGES).len() > 1);
    }

    #[test]
    fn fixed_step_order_is_eight() {
        // Global error of an order-p method scales as h^p: the ratio for halved h is 2^p.
        let err = |steps: usize| {
            let mut s = Dop853::new(2, 1e-12, 1e-12);
            let mut f = osc;
            s.start(&mut f, 0.0, &[1.0, 0.0], 4.0);
            let h = 4.0 / steps as f64;
            for _ in 0..steps {
                s.step_fixed(&mut f, h);
            }
            (s.y[0] - 4f64.cos()).abs().max((s.y[1] + 4f64.sin()).abs())
        };
        let (e1, e2) = (err(8), err(16));
        let p = (e1 / e2).log2();
        assert!((p - 8.0).abs() < 0.5, "observed order {p} ({e1:e}, {e2:e})");
    }

    #[test]
    fn dense_output_is_accurate_inside_steps() {
        // Dense output of DOP853 has order 7: a local interpolation error ~ h^8.
        let worst = |h: f64| {
            let mut s = Dop853::new(2, 1e-12, 1e-12);
            let mut f = osc;
            s.start(&mut f, 0.0, &[1.0, 0.0], 1.0);
            s.step_fixed(&mut f, h);
            s.prepare_dense(&mut f);
            let mut out = [0.0; 2];
            let mut w: f64 = 0.0;
            for k in 1..10 {
                let t = h * k as f64 / 10.0;
                s.dense(t, &mut out);
                w = w
                    .max((out[0] - t.cos()).abs())
                    .max((out[1] + t.sin()).abs());
            }
            w
        };
        let (a, b) = (worst(0.8), worst(0.4));
        assert!(a < 1e-6, "dense error {a:e} {b:e}");
        let p = (a / b).log2();
        assert!(p > 7.0, "dense local order {p}");
    }

    #[test]
    fn adaptive_meets_tight_tolerance() {
        // 20 periods of the oscillator at rtol = atol = 1e-12 must stay within ~1e-10.
        let mut s = Dop853::new(2, 1e-12, 1e-12);
        let mut f = osc;
        let t_end = 40.0 * std::f64::consts::PI;
        s.start(&mut f, 0.0, &[1.0, 0.0], t_end);
        while s.t < t_end {
            s.step(&mut f, t_end).unwrap();
        }
        assert_eq!(s.t, t_end);
        assert!((s.y[0] - 1.0).abs() < 1e-10, "{}", s.y[0] - 1.0);
        assert!(s.y[1].abs() < 1e-10);
        assert!(s.stats.rejected < s.stats.steps / 5 + 3);
    }
}
