//! A primal–dual interior-point solver for the LP of one SLP iteration ([`crate::slp`]),
//! specialised to its shape: a few hundred variables with box bounds, sparse rows, and one
//! elastic slack per constraint row.
//!
//! The LP, in the variables `y` (the step and the minimax bound) and `σ` (one elastic slack
//! per elastic row):
//!
//! `min c·y + μ Σ σ_j  s.t.  lo <= y <= hi,  a_r·y <= b_r,  e_j·y − σ_j <= f_j,  σ >= 0`
//!
//! (bounds may be infinite). Written as `G z + s = h`, `s >= 0`, with the dual `λ >= 0`, it
//! is solved by Mehrotra's predictor–corrector method (Wright, *Primal-Dual Interior-Point
//! Methods*, SIAM 1997, ch. 10; the starting point of §10.2): each Newton system is reduced
//! to the normal equations `Gᵀ W G Δz = r`, `W = diag(λ/s)`. The slack `σ_j` appears in two
//! rows only (its elastic row and `σ_j >= 0`), so it is eliminated exactly: the normal matrix
//! of `y` is `Σ w_bounds + Σ_r w_r a_r a_rᵀ + Σ_j (w_e w_s / (w_e + w_s))_j e_j e_jᵀ`, dense
//! of the size of `y`, factored by Cholesky; `Δσ` follows row by row.
//!
//! Why not clarabel, the workspace's conic solver, which [`crate::slp`] used before and
//! still falls back to: clarabel factors the sparse quasi-definite KKT system of all
//! variables and rows (about 1 200 variables and 3 000 rows for a blade side), with
//! iterative refinement; it took 50–110 ms per LP of the impeller-8+8 blade finishing, about
//! half the operation's planning time. The reduced system here is 183 × 183.
//!
//! Tolerances: relative primal and dual residuals and the complementarity gap below
//! [`TOLERANCE`] (clarabel's defaults); at most [`MAX_ITERATIONS`] iterations, after which
//! (or when the normal matrix is not numerically positive definite) the solve reports
//! [`LpFailure`] and the caller falls back to clarabel.
//!
//! Cost per iteration: assembling the normal matrix, `O(Σ_rows nnz²)`, one dense Cholesky,
//! `p³/6` multiply–adds for `p` variables in `y`, and two triangular solve pairs (predictor
//! and corrector). Working memory is allocated once per solve.

// The iteration works on parallel vectors over the inequalities, addressed by block offsets
// (bounds, rows, elastic rows, slack signs): index loops say that more plainly than zips.
#![allow(clippy::needless_range_loop)]

/// Pivots of the unit-diagonal normal matrix below this are taken as zero ([`PIVOT_BIG`]).
const PIVOT_EPS: f64 = 1e-13;
/// The factor's diagonal entry that replaces a vanishing pivot.
const PIVOT_BIG: f64 = 1e64;

/// Relative feasibility and gap tolerance of a solve.
pub const TOLERANCE: f64 = 1e-8;
/// Iteration limit of a solve.
pub const MAX_ITERATIONS: usize = 80;
/// Fraction of the step to the boundary of the positive orthant taken per iteration.
const STEP_FRACTION: f64 = 0.99;

/// Sparse rows in compressed form (entries of each row sorted by variable, duplicates
/// summed). Rows with the same variables form a group, whose contribution to the normal
/// matrix is accumulated densely before it is scattered once (the rows of the SLP share few
/// patterns: the two rows of a minimax sample, all samples in one knot span of the path).
#[derive(Debug, Clone)]
pub struct SparseRows {
    ptr: Vec<usize>,
    idx: Vec<usize>,
    val: Vec<f64>,
    /// Rows of each group.
    groups: Vec<Vec<usize>>,
    /// Group of each variable pattern.
    pattern: std::collections::HashMap<Vec<usize>, usize>,
}

impl Default for SparseRows {
    fn default() -> Self {
        Self::new()
    }
}

impl SparseRows {
    /// No rows.
    pub fn new() -> Self {
        SparseRows {
            ptr: vec![0],
            idx: Vec::new(),
            val: Vec::new(),
            groups: Vec::new(),
            pattern: std::collections::HashMap::new(),
        }
    }
    /// Appends a row from `(variable, coefficient)` entries in any order.
    pub fn push(&mut self, entries: impl IntoIterator<Item = (usize, f64)>) {
        let start = self.idx.len();
        for (k, v) in entries {
            self.idx.push(k);
            self.val.push(v);
        }
        // Sort the new row's entries by variable (insertion sort: rows are short) and sum
        // duplicates.
        let end = self.idx.len();
        for a in start + 1..end {
            let mut b = a;
            while b > start && self.idx[b - 1] > self.idx[b] {
                self.idx.swap(b - 1, b);
                self.val.swap(b - 1, b);
                b -= 1;
            }
        }
        let mut w = start;
        for r in start..end {
            if w > start && self.idx[w - 1] == self.idx[r] {
                self.val[w - 1] += self.val[r];
            } else {
                self.idx[w] = self.idx[r];
                self.val[w] = self.val[r];
                w += 1;
            }
        }
        self.idx.truncate(w);
        self.val.truncate(w);
        self.ptr.push(w);
        let r = self.ptr.len() - 2;
        // A pattern seen before is looked up without copying it.
        let g = match self.pattern.get(&self.idx[start..w]) {
            Some(&g) => g,
            None => {
                let g = self.groups.len();
                self.pattern.insert(self.idx[start..w].to_vec(), g);
                self.groups.push(Vec::new());
                g
            }
        };
        self.groups[g].push(r);
    }
    /// Number of rows.
    pub fn len(&self) -> usize {
        self.ptr.len().saturating_sub(1)
    }
    /// True without rows.
    pub fn is_empty(&self) -> bool {
        self.len() == 0
    }
    fn row(&self, r: usize) -> (&[usize], &[f64]) {
        let (a, b) = (self.ptr[r], self.ptr[r + 1]);
        (&self.idx[a..b], &self.val[a..b])
    }
    fn dot(&self, r: usize, y: &[f64]) -> f64 {
        let (i, v) = self.row(r);
        i.iter().zip(v).map(|(&k, &a)| a * y[k]).sum()
    }
    fn axpy(&self, r: usize, alpha: f64, out: &mut [f64]) {
        let (i, v) = self.row(r);
        for (&k, &a) in i.iter().zip(v) {
            out[k] += alpha * a;
        }
    }
    /// `M += Σ_r w_r a_r a_rᵀ` over all rows, on the lower triangle of the row-major
    /// `p × p` matrix `m`; each group is summed in the dense `local` block first.
    fn add_gram(&self, w: impl Fn(usize) -> f64, m: &mut [f64], p: usize, local: &mut Vec<f64>) {
        for rows in &self.groups {
            let Some(&first) = rows.first() else {
                continue;
            };
            let idx = &self.idx[self.ptr[first]..self.ptr[first + 1]];
            let k = idx.len();
            local.clear();
            local.resize(k * k, 0.0);
            for &r in rows {
                let v = &self.val[self.ptr[r]..self.ptr[r + 1]];
                let wr = w(r);
                for a in 0..k {
                    let wa = wr * v[a];
                    for (l, vb) in local[a * k..a * k + a + 1].iter_mut().zip(v) {
                        *l += wa * vb;
                    }
                }
            }
            for a in 0..k {
                for b in 0..=a {
                    m[idx[a] * p + idx[b]] += local[a * k + b];
                }
            }
        }
    }
}

/// The LP of the module docs.
#[derive(Debug, Clone)]
pub struct ElasticLp {
    /// Cost of `y`.
    pub cost: Vec<f64>,
    /// Lower bounds of `y` (may be `-∞`).
    pub lower: Vec<f64>,
    /// Upper bounds of `y` (may be `+∞`).
    pub upper: Vec<f64>,
    /// Plain rows `a_r·y <= b_r`.
    pub rows: SparseRows,
    /// Right-hand sides `b_r`.
    pub rhs: Vec<f64>,
    /// Elastic rows `e_j·y − σ_j <= f_j`.
    pub elastic: SparseRows,
    /// Right-hand sides `f_j`.
    pub elastic_rhs: Vec<f64>,
    /// Cost `μ > 0` of each elastic slack.
    pub penalty: f64,
}

/// A solution of [`ElasticLp`].
#[derive(Debug, Clone)]
pub struct LpSolution {
    /// Optimal `y`.
    pub y: Vec<f64>,
    /// Optimal elastic slacks.
    pub sigma: Vec<f64>,
    /// Interior-point iterations.
    pub iterations: usize,
}

/// Why a solve gave up (the caller falls back to another solver).
#[derive(Debug, Clone, PartialEq)]
pub struct LpFailure(pub String);

/// Vectors over the inequalities, in the order: finite upper bounds, finite lower bounds,
/// plain rows, elastic rows, slack sign rows.
struct Layout {
    p: usize,
    q: usize,
    up: Vec<usize>,
    lo: Vec<usize>,
    nr: usize,
}

impl Layout {
    fn m(&self) -> usize {
        self.up.len() + self.lo.len() + self.nr + 2 * self.q
    }
    fn ol(&self) -> usize {
        self.up.len()
    }
    fn or(&self) -> usize {
        self.up.len() + self.lo.len()
    }
    fn oe(&self) -> usize {
        self.or() + self.nr
    }
    fn os(&self) -> usize {
        self.oe() + self.q
    }
}

/// Working state of one solve.
struct Ipm<'a> {
    lp: &'a ElasticLp,
    lay: Layout,
    h: Vec<f64>,
    /// Normal matrix (row-major, lower triangle), then its scaled Cholesky factor.
    mat: Vec<f64>,
    /// Elastic-slack pivots `w_e + w_s`.
    dsig: Vec<f64>,
    w: Vec<f64>,
    /// Dense block of a row group.
    local: Vec<f64>,
    /// Diagonal scaling `D` of the normal matrix.
    dscale: Vec<f64>,
}

impl<'a> Ipm<'a> {
    /// `out = G z` for `z = (y, σ)`.
    fn g_times(&self, y: &[f64], sig: &[f64], out: &mut [f64]) {
        let l = &self.lay;
        for (o, &k) in out.iter_mut().zip(&l.up) {
            *o = y[k];
        }
        for (o, &k) in out[l.ol()..].iter_mut().zip(&l.lo) {
            *o = -y[k];
        }
        for r in 0..l.nr {
            out[l.or() + r] = self.lp.rows.dot(r, y);
        }
        for j in 0..l.q {
            out[l.oe() + j] = self.lp.elastic.dot(j, y) - sig[j];
            out[l.os() + j] = -sig[j];
        }
    }

    /// `(gy, gσ) = Gᵀ v`.
    fn gt_times(&self, v: &[f64], gy: &mut [f64], gs: &mut [f64]) {
        let l = &self.lay;
        gy.iter_mut().for_each(|x| *x = 0.0);
        for (i, &k) in l.up.iter().enumerate() {
            gy[k] += v[i];
        }
        for (i, &k) in l.lo.iter().enumerate() {
            gy[k] -= v[l.ol() + i];
        }
        for r in 0..l.nr {
            self.lp.rows.axpy(r, v[l.or() + r], gy);
        }
        for j in 0..l.q {
            self.lp.elastic.axpy(j, v[l.oe() + j], gy);
            gs[j] = -v[l.oe() + j] - v[l.os() + j];
        }
    }

    /// Assembles `Gᵀ W G` with `σ` eliminated and factors it (`self.w` holds `W`): the
    /// matrix is scaled to a unit diagonal, `S = D M D`, and factored, `S = L Lᵀ`
    /// ([`cholesky`]).
    fn factor(&mut self) -> Result<(), LpFailure> {
        let l = &self.lay;
        let p = l.p;
        self.mat.iter_mut().for_each(|x| *x = 0.0);
        for (i, &k) in l.up.iter().enumerate() {
            self.mat[k * p + k] += self.w[i];
        }
        for (i, &k) in l.lo.iter().enumerate() {
            self.mat[k * p + k] += self.w[l.ol() + i];
        }
        let (or, oe, os) = (l.or(), l.oe(), l.os());
        let w = &self.w;
        self.lp
            .rows
            .add_gram(|r| w[or + r], &mut self.mat, p, &mut self.local);
        for j in 0..l.q {
            self.dsig[j] = w[oe + j] + w[os + j];
        }
        let dsig = &self.dsig;
        self.lp.elastic.add_gram(
            |j| w[oe + j] * w[os + j] / dsig[j],
            &mut self.mat,
            p,
            &mut self.local,
        );
        for k in 0..p {
            let d = self.mat[k * p + k];
            if !d.is_finite() {
                return Err(LpFailure(format!("non-finite normal matrix at {k}")));
            }
            self.dscale[k] = if d > 0.0 { 1.0 / d.sqrt() } else { 1.0 };
        }
        for i in 0..p {
            for j in 0..=i {
                self.mat[i * p + j] *= self.dscale[i] * self.dscale[j];
            }
        }
        cholesky(&mut self.mat, p);
        Ok(())
    }

    /// Solves `Gᵀ W G (Δy, Δσ) = (ry, rσ)` with the factor of [`Ipm::factor`], in place.
    fn solve_normal(&self, ry: &mut [f64], rs: &mut [f64]) {
        let l = &self.lay;
        for j in 0..l.q {
            let we = self.w[l.oe() + j];
            self.lp.elastic.axpy(j, we * rs[j] / self.dsig[j], ry);
        }
        for (r, d) in ry.iter_mut().zip(&self.dscale) {
            *r *= d;
        }
        cholesky_solve(&self.mat, l.p, ry);
        for (r, d) in ry.iter_mut().zip(&self.dscale) {
            *r *= d;
        }
        for j in 0..l.q {
            let we = self.w[l.oe() + j];
            rs[j] = (rs[j] + we * self.lp.elastic.dot(j, ry)) / self.dsig[j];
        }
    }
}

/// In-place Cholesky `S = L Lᵀ` of the lower triangle of a row-major `p × p` matrix with a
/// unit diagonal. Near the optimum the weights `λ/s` span many orders of magnitude and a
/// pivot can vanish in rounding (the columns of variables fixed at the optimum become
/// dependent): a pivot below [`PIVOT_EPS`] gets the factor entry [`PIVOT_BIG`], which zeroes
/// that component of the step (the remedy of Zhang's LIPSOL; Wright, ch. 11). Plain scalar
/// code (no run-time SIMD dispatch), so a solve gives the same bits on every x86-64 machine
/// and the regression bounds on move counts hold everywhere. `p³/6` multiply–adds.
fn cholesky(m: &mut [f64], p: usize) {
    for j in 0..p {
        let (upto, rest) = m.split_at_mut((j + 1) * p);
        let rowj = &mut upto[j * p..];
        let d = rowj[j] - dot(&rowj[..j], &rowj[..j]);
        let d = if d > PIVOT_EPS { d.sqrt() } else { PIVOT_BIG };
        rowj[j] = d;
        let inv = 1.0 / d;
        let lj = &rowj[..j];
        for rowi in rest.chunks_exact_mut(p) {
            rowi[j] = (rowi[j] - dot(&rowi[..j], lj)) * inv;
        }
    }
}

/// Solves `L Lᵀ x = b` in place (`L` from [`cholesky`]).
fn cholesky_solve(l: &[f64], p: usize, b: &mut [f64]) {
    for i in 0..p {
        let s = dot(&l[i * p..i * p + i], &b[..i]);
        b[i] = (b[i] - s) / l[i * p + i];
    }
    for i in (0..p).rev() {
        let mut s = b[i];
        for k in i + 1..p {
            s -= l[k * p + i] * b[k];
        }
        b[i] = s / l[i * p + i];
    }
}

/// Dot product with four accumulators (so the compiler vectorises it).
fn dot(a: &[f64], b: &[f64]) -> f64 {
    let mut acc = [0.0f64; 4];
    let n4 = a.len() / 4 * 4;
    for (x, y) in a[..n4].chunks_exact(4).zip(b[..n4].chunks_exact(4)) {
        for k in 0..4 {
            acc[k] += x[k] * y[k];
        }
    }
    let mut s = (acc[0] + acc[1]) + (acc[2] + acc[3]);
    for k in n4..a.len() {
        s += a[k] * b[k];
    }
    s
}

fn norm_inf(v: &[f64]) -> f64 {
    v.iter().fold(0.0, |a, x| a.max(x.abs()))
}

/// Largest `α > 0` with `v + α dv >= 0` (`∞` when no component decreases).
fn max_step(v: &[f64], dv: &[f64]) -> f64 {
    v.iter().zip(dv).fold(
        f64::INFINITY,
        |a, (&x, &d)| {
            if d < 0.0 {
                a.min(-x / d)
            } else {
                a
            }
        },
    )
}

/// Solves `lp` (module docs). Errors when the iteration limit is reached or the normal
/// matrix is not numerically positive definite.
pub fn solve(lp: &ElasticLp) -> Result<LpSolution, LpFailure> {
    let p = lp.cost.len();
    let q = lp.elastic.len();
    if lp.lower.len() != p
        || lp.upper.len() != p
        || lp.rhs.len() != lp.rows.len()
        || lp.elastic_rhs.len() != q
        || lp.rows.idx.iter().chain(&lp.elastic.idx).any(|&k| k >= p)
    {
        return Err(LpFailure("inconsistent LP dimensions".into()));
    }
    let lay = Layout {
        p,
        q,
        up: (0..p).filter(|&k| lp.upper[k].is_finite()).collect(),
        lo: (0..p).filter(|&k| lp.lower[k].is_finite()).collect(),
        nr: lp.rows.len(),
    };
    let m = lay.m();
    let mut h = Vec::with_capacity(m);
    h.extend(lay.up.iter().map(|&k| lp.upper[k]));
    h.extend(lay.lo.iter().map(|&k| -lp.lower[k]));
    h.extend_from_slice(&lp.rhs);
    h.extend_from_slice(&lp.elastic_rhs);
    h.extend(std::iter::repeat_n(0.0, q));
    let mut ipm = Ipm {
        lp,
        lay,
        h,
        mat: vec![0.0; p * p],
        dsig: vec![0.0; q],
        w: vec![1.0; m],
        local: Vec::new(),
        dscale: vec![1.0; p],
    };
    let cs = vec![lp.penalty; q];

    // Starting point (Wright §10.2): least-squares primal `min ‖s‖` with `G z + s = h` and
    // least-norm dual `Gᵀ λ = −c`, both shifted into the interior.
    ipm.factor()?;
    let mut y = vec![0.0; p];
    let mut sig = vec![0.0; q];
    ipm.gt_times(&ipm.h, &mut y, &mut sig);
    ipm.solve_normal(&mut y, &mut sig);
    let mut s = vec![0.0; m];
    ipm.g_times(&y, &sig, &mut s);
    for (si, hi) in s.iter_mut().zip(&ipm.h) {
        *si = hi - *si;
    }
    let mut wy: Vec<f64> = lp.cost.iter().map(|c| -c).collect();
    let mut ws: Vec<f64> = cs.iter().map(|c| -c).collect();
    ipm.solve_normal(&mut wy, &mut ws);
    let mut lam = vec![0.0; m];
    ipm.g_times(&wy, &ws, &mut lam);
    let ds = (-1.5 * s.iter().fold(f64::INFINITY, |a, &x| a.min(x))).max(0.0);
    let dl = (-1.5 * lam.iter().fold(f64::INFINITY, |a, &x| a.min(x))).max(0.0);
    s.iter_mut().for_each(|x| *x += ds);
    lam.iter_mut().for_each(|x| *x += dl);
    let sl: f64 = s.iter().zip(&lam).map(|(a, b)| a * b).sum();
    let (sum_s, sum_l): (f64, f64) = (s.iter().sum(), lam.iter().sum());
    let (ds2, dl2) = (0.5 * sl / sum_l.max(1e-300), 0.5 * sl / sum_s.max(1e-300));
    s.iter_mut().for_each(|x| *x = (*x + ds2).max(1e-8));
    lam.iter_mut().for_each(|x| *x = (*x + dl2).max(1e-8));

    let scale_p = 1.0 + norm_inf(&ipm.h);
    let scale_d = 1.0 + norm_inf(&lp.cost).max(lp.penalty);
    let mut rp = vec![0.0; m];
    let mut rdy = vec![0.0; p];
    let mut rds = vec![0.0; q];
    let mut gz = vec![0.0; m];
    let mut rc = vec![0.0; m];
    let mut t = vec![0.0; m];
    let mut dy = vec![0.0; p];
    let mut dsg = vec![0.0; q];
    let mut dlam = vec![0.0; m];
    let mut dsl = vec![0.0; m];
    let mut dlam_a = vec![0.0; m];
    let mut dsl_a = vec![0.0; m];
    for it in 0..MAX_ITERATIONS {
        // Residuals r_p = G z + s − h, r_d = Gᵀ λ + c.
        ipm.g_times(&y, &sig, &mut gz);
        for i in 0..m {
            rp[i] = gz[i] + s[i] - ipm.h[i];
        }
        ipm.gt_times(&lam, &mut rdy, &mut rds);
        for (r, c) in rdy.iter_mut().zip(&lp.cost) {
            *r += c;
        }
        for r in rds.iter_mut() {
            *r += lp.penalty;
        }
        let gap: f64 = s.iter().zip(&lam).map(|(a, b)| a * b).sum();
        let pcost: f64 = dot(&lp.cost, &y) + lp.penalty * sig.iter().sum::<f64>();
        let dcost: f64 = -dot(&ipm.h, &lam);
        let pres = norm_inf(&rp) / scale_p;
        let dres = norm_inf(&rdy).max(norm_inf(&rds)) / scale_d;
        if pres < TOLERANCE
            && dres < TOLERANCE
            && (gap < TOLERANCE || gap < TOLERANCE * pcost.abs().min(dcost.abs()))
        {
            return Ok(LpSolution {
                y,
                sigma: sig,
                iterations: it,
            });
        }
        let mu = gap / m as f64;
        for i in 0..m {
            ipm.w[i] = lam[i] / s[i];
        }
        ipm.factor()?;
        // Predictor (rc = −s∘λ), then the corrector with the centring σμ and the
        // second-order term −Δs_aff∘Δλ_aff.
        for pass in 0..2 {
            if pass == 0 {
                for i in 0..m {
                    rc[i] = -s[i] * lam[i];
                }
            } else {
                let a = max_step(&s, &dsl_a).min(max_step(&lam, &dlam_a)).min(1.0);
                let gap_aff: f64 = (0..m)
                    .map(|i| (s[i] + a * dsl_a[i]) * (lam[i] + a * dlam_a[i]))
                    .sum();
                let centring = (gap_aff / gap).powi(3);
                for i in 0..m {
                    rc[i] = -s[i] * lam[i] - dsl_a[i] * dlam_a[i] + centring * mu;
                }
            }
            // t = W r_p + rc/s; N Δz = −r_d − Gᵀ t.
            for i in 0..m {
                t[i] = ipm.w[i] * rp[i] + rc[i] / s[i];
            }
            ipm.gt_times(&t, &mut dy, &mut dsg);
            for k in 0..p {
                dy[k] = -rdy[k] - dy[k];
            }
            for j in 0..q {
                dsg[j] = -rds[j] - dsg[j];
            }
            ipm.solve_normal(&mut dy, &mut dsg);
            // Δλ = W G Δz + t, Δs = (rc − s∘Δλ)/λ.
            ipm.g_times(&dy, &dsg, &mut gz);
            for i in 0..m {
                dlam[i] = ipm.w[i] * gz[i] + t[i];
                dsl[i] = (rc[i] - s[i] * dlam[i]) / lam[i];
            }
            if pass == 0 {
                dlam_a.copy_from_slice(&dlam);
                dsl_a.copy_from_slice(&dsl);
            }
        }
        let a = (STEP_FRACTION * max_step(&s, &dsl).min(max_step(&lam, &dlam))).min(1.0);
        for k in 0..p {
            y[k] += a * dy[k];
        }
        for j in 0..q {
            sig[j] += a * dsg[j];
        }
        for i in 0..m {
            s[i] += a * dsl[i];
            lam[i] += a * dlam[i];
        }
        if !y.iter().chain(&s).chain(&lam).all(|v| v.is_finite()) {
            return Err(LpFailure(format!("non-finite iterate at iteration {it}")));
        }
    }
    Err(LpFailure(format!(
        "no convergence in {MAX_ITERATIONS} iterations"
    )))
}

#[cfg(test)]
mod tests {
    use super::*;
    use clarabel::algebra::CscMatrix;
    use clarabel::solver::{DefaultSettingsBuilder, DefaultSolver, IPSolver, NonnegativeConeT};
    use proptest::prelude::*;

    fn objective(lp: &ElasticLp, s: &LpSolution) -> f64 {
        dot(&lp.cost, &s.y) + lp.penalty * s.sigma.iter().sum::<f64>()
    }

    /// Largest violation of the bounds, rows and elastic rows (with σ >= 0) at a solution.
    fn violation(lp: &ElasticLp, s: &LpSolution) -> f64 {
        let mut v = 0.0f64;
        for k in 0..lp.cost.len() {
            v = v.max(lp.lower[k] - s.y[k]).max(s.y[k] - lp.upper[k]);
        }
        for r in 0..lp.rows.len() {
            v = v.max(lp.rows.dot(r, &s.y) - lp.rhs[r]);
        }
        for j in 0..lp.elastic.len() {
            v = v.max(lp.elastic.dot(j, &s.y) - s.sigma[j] - lp.elastic_rhs[j]);
            v = v.max(-s.sigma[j]);
        }
        v
    }

    /// The same LP by clarabel: its optimal objective.
    fn clarabel_objective(lp: &ElasticLp) -> f64 {
        let (p, q) = (lp.cost.len(), lp.elastic.len());
        let n = p + q;
        let mut cols: Vec<Vec<(usize, f64)>> = vec![Vec::new(); n];
        let mut b = Vec::new();
        let mut row = 0;
        let mut push = |entries: Vec<(usize, f64)>, rhs: f64, b: &mut Vec<f64>| {
            for (k, v) in entries {
                cols[k].push((row, v));
            }
            b.push(rhs);
            row += 1;
        };
        for k in 0..p {
            if lp.upper[k].is_finite() {
                push(vec![(k, 1.0)], lp.upper[k], &mut b);
            }
            if lp.lower[k].is_finite() {
                push(vec![(k, -1.0)], -lp.lower[k], &mut b);
            }
        }
        for r in 0..lp.rows.len() {
            let (i, v) = lp.rows.row(r);
            push(
                i.iter().copied().zip(v.iter().copied()).collect(),
                lp.rhs[r],
                &mut b,
            );
        }
        for j in 0..q {
            let (i, v) = lp.elastic.row(j);
            let mut e: Vec<_> = i.iter().copied().zip(v.iter().copied()).collect();
            e.push((p + j, -1.0));
            push(e, lp.elastic_rhs[j], &mut b);
            push(vec![(p + j, -1.0)], 0.0, &mut b);
        }
        let m = b.len();
        let mut colptr = vec![0];
        let (mut rowval, mut nzval) = (Vec::new(), Vec::new());
        for c in &cols {
            for &(r, v) in c {
                rowval.push(r);
                nzval.push(v);
            }
            colptr.push(rowval.len());
        }
        let a = CscMatrix::new(m, n, colptr, rowval, nzval);
        let mut c = lp.cost.clone();
        c.extend(std::iter::repeat_n(lp.penalty, q));
        let settings = DefaultSettingsBuilder::default()
            .verbose(false)
            .build()
            .unwrap();
        let mut solver = DefaultSolver::new(
            &CscMatrix::zeros((n, n)),
            &c,
            &a,
            &b,
            &[NonnegativeConeT(m)],
            settings,
        )
        .unwrap();
        solver.solve();
        solver.solution.obj_val
    }

    /// `min −x − y` s.t. `x + 2y <= 4`, `3x + y <= 6`, `0 <= x, y <= 10`: the vertex
    /// (1.6, 1.2), objective −2.8.
    #[test]
    fn textbook_vertex() {
        let mut rows = SparseRows::new();
        rows.push([(0, 1.0), (1, 2.0)]);
        rows.push([(1, 1.0), (0, 3.0)]);
        let lp = ElasticLp {
            cost: vec![-1.0, -1.0],
            lower: vec![0.0; 2],
            upper: vec![10.0; 2],
            rows,
            rhs: vec![4.0, 6.0],
            elastic: SparseRows::new(),
            elastic_rhs: Vec::new(),
            penalty: 1.0,
        };
        let s = solve(&lp).unwrap();
        assert!(
            (s.y[0] - 1.6).abs() < 1e-7 && (s.y[1] - 1.2).abs() < 1e-7,
            "{:?}",
            s.y
        );
        assert!((objective(&lp, &s) + 2.8).abs() < 1e-7);
    }

    /// Contradictory elastic rows `x >= 1` and `x <= −1` (penalty 3) with a free `x` cost
    /// 0.5·x on `[−5, 5]`: any `x ∈ [−1, 1]` pays 3·2 = 6 in slacks, so `x = −1` and the
    /// objective is 5.5.
    #[test]
    fn elastic_rows_pay_their_penalty() {
        let mut elastic = SparseRows::new();
        elastic.push([(0, -1.0)]); // −x − σ <= −1
        elastic.push([(0, 1.0)]); // x − σ <= −1
        let lp = ElasticLp {
            cost: vec![0.5],
            lower: vec![-5.0],
            upper: vec![5.0],
            rows: SparseRows::new(),
            rhs: Vec::new(),
            elastic,
            elastic_rhs: vec![-1.0, -1.0],
            penalty: 3.0,
        };
        let s = solve(&lp).unwrap();
        assert!((s.y[0] + 1.0).abs() < 1e-6, "{:?}", s.y);
        assert!((objective(&lp, &s) - 5.5).abs() < 1e-6);
        assert!(violation(&lp, &s) < 1e-8);
    }

    #[test]
    fn rows_are_sorted_merged_and_grouped_by_pattern() {
        assert!(SparseRows::default().is_empty());
        let mut r = SparseRows::default();
        r.push([(3, 1.0), (1, 2.0), (3, 4.0)]);
        r.push([(1, -1.0), (3, 0.5)]);
        r.push([(0, 1.0)]);
        assert_eq!(r.row(0), (&[1usize, 3][..], &[2.0, 5.0][..]));
        assert_eq!(r.groups, vec![vec![0, 1], vec![2]]);
        // The grouped Gram matrix equals the sum of the rows' outer products.
        let p = 4;
        let mut m = vec![0.0; p * p];
        let w = [2.0, 3.0, 0.5];
        r.add_gram(|k| w[k], &mut m, p, &mut Vec::new());
        let dense = [
            [0.0, 2.0, 0.0, 5.0],
            [0.0, -1.0, 0.0, 0.5],
            [1.0, 0.0, 0.0, 0.0],
        ];
        for i in 0..p {
            for j in 0..=i {
                let want: f64 = (0..3).map(|k| w[k] * dense[k][i] * dense[k][j]).sum();
                assert!((m[i * p + j] - want).abs() < 1e-12, "({i}, {j})");
            }
        }
    }

    /// Random LPs of the SLP's shape (boxed variables, one free, sparse rows, elastic rows):
    /// the optimum equals clarabel's and the solution is feasible.
    fn random_lp() -> impl Strategy<Value = ElasticLp> {
        (2usize..8, 0usize..10, 0usize..8, 0.5f64..50.0)
            .prop_flat_map(|(p, nr, q, mu)| {
                let row = proptest::collection::vec((0..p + 1, -3.0f64..3.0), 1..5);
                (
                    proptest::collection::vec(-2.0f64..2.0, p),
                    proptest::collection::vec(0.01f64..2.0, p),
                    proptest::collection::vec((row.clone(), -2.0f64..2.0), nr),
                    proptest::collection::vec((row, -2.0f64..2.0), q),
                    Just(mu),
                )
            })
            .prop_map(|(cost, half, rows_in, el_in, mu)| {
                let p = cost.len();
                // Variable p (the last) is free, like the minimax bound `t`, with cost 1 and
                // kept bounded below by |y_0 − 0.3| <= t.
                let mut cost = cost;
                cost.push(1.0);
                let mut lower: Vec<f64> = half.iter().map(|h| -h).collect();
                let mut upper = half;
                lower.push(f64::NEG_INFINITY);
                upper.push(f64::INFINITY);
                let mut rows = SparseRows::new();
                let mut rhs = Vec::new();
                rows.push([(0, 1.0), (p, -1.0)]);
                rhs.push(0.3);
                rows.push([(0, -1.0), (p, -1.0)]);
                rhs.push(-0.3);
                for (r, b) in rows_in {
                    // Plain rows keep 0 feasible: b >= 0 (the SLP's zero step is feasible up
                    // to the elastic rows).
                    rows.push(r.into_iter().filter(|e| e.0 < p));
                    rhs.push(b.abs());
                }
                let mut elastic = SparseRows::new();
                let mut elastic_rhs = Vec::new();
                for (r, f) in el_in {
                    elastic.push(r.into_iter().filter(|e| e.0 < p));
                    elastic_rhs.push(f);
                }
                ElasticLp {
                    cost,
                    lower,
                    upper,
                    rows,
                    rhs,
                    elastic,
                    elastic_rhs,
                    penalty: mu,
                }
            })
    }

    proptest! {
        #![proptest_config(ProptestConfig::with_cases(200))]
        #[test]
        fn matches_clarabel_on_random_lps(lp in random_lp()) {
            let s = solve(&lp).map_err(|e| TestCaseError::fail(e.0))?;
            let ours = objective(&lp, &s);
            let theirs = clarabel_objective(&lp);
            prop_assert!(violation(&lp, &s) < 1e-7, "violation {}", violation(&lp, &s));
            prop_assert!(
                (ours - theirs).abs() <= 1e-6 * (1.0 + theirs.abs()),
                "ours {ours} clarabel {theirs}"
            );
        }
    }
}
