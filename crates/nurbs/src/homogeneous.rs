//! The knot algorithms of The NURBS Book chapter 5 on one homogeneous control polygon
//! (`(w P, w)` or plain `P`, stored flat with a fixed stride): knot insertion (A5.1),
//! knot refinement (A5.4), degree elevation (A5.9), clamping and reversal. Curves use them
//! directly; surfaces apply them to every row or column of the net.
//!
//! Inputs are assumed valid here (callers validate parameters and multiplicities first).

/// A B-spline control polygon in homogeneous coordinates.
#[derive(Debug, Clone, PartialEq)]
pub(crate) struct HSpline {
    pub p: usize,
    pub knots: Vec<f64>,
    /// `n_ctrl * dim` coordinates.
    pub pts: Vec<f64>,
    pub dim: usize,
}

/// In-place `v[i] = alpha v[i] + (1 - alpha) v[j]` for points `i`, `j` of a flat array.
#[inline]
fn blend_in(v: &mut [f64], dim: usize, i: usize, j: usize, alpha: f64) {
    for c in 0..dim {
        v[i * dim + c] = alpha * v[i * dim + c] + (1.0 - alpha) * v[j * dim + c];
    }
}

#[inline]
fn copy_pt(dst: &mut [f64], dim: usize, i: usize, src: &[f64], j: usize) {
    dst[i * dim..(i + 1) * dim].copy_from_slice(&src[j * dim..(j + 1) * dim]);
}

impl HSpline {
    pub fn n_ctrl(&self) -> usize {
        self.pts.len() / self.dim
    }

    /// Index `k` of the last knot `<= u` (the span A5.1 inserts into; needs
    /// `u_p <= u < u_{m-p}`).
    pub fn insertion_span(&self, u: f64) -> usize {
        self.knots.partition_point(|&k| k <= u) - 1
    }

    /// Inserts `u` `r` times (NURBS Book A5.1, O(r p dim + n dim)). Needs
    /// `u_p <= u < u_{m-p}` and `multiplicity(u) + r <= p` (or `<= p + 1` at the domain
    /// start when clamping).
    pub fn insert(&self, u: f64, r: usize) -> HSpline {
        if r == 0 {
            return self.clone();
        }
        let (p, dim) = (self.p, self.dim);
        let up = &self.knots;
        let np = self.n_ctrl() - 1;
        let mp = np + p + 1;
        let k = self.insertion_span(u);
        let s = up.iter().filter(|&&x| x == u).count();
        let mut uq = Vec::with_capacity(up.len() + r);
        uq.extend_from_slice(&up[..=k]);
        uq.extend(std::iter::repeat_n(u, r));
        uq.extend_from_slice(&up[k + 1..=mp]);
        let pw = &self.pts;
        let mut qw = vec![0.0; (np + 1 + r) * dim];
        for i in 0..=(k - p) {
            copy_pt(&mut qw, dim, i, pw, i);
        }
        for i in (k - s)..=np {
            copy_pt(&mut qw, dim, i + r, pw, i);
        }
        let mut rw = vec![0.0; (p - s + 1) * dim];
        for i in 0..=(p - s) {
            copy_pt(&mut rw, dim, i, pw, k - p + i);
        }
        let mut l = k - p;
        for j in 1..=r {
            l = k - p + j;
            for i in 0..=(p - j - s) {
                let alpha = (u - up[l + i]) / (up[i + k + 1] - up[l + i]);
                for c in 0..dim {
                    rw[i * dim + c] =
                        alpha * rw[(i + 1) * dim + c] + (1.0 - alpha) * rw[i * dim + c];
                }
            }
            copy_pt(&mut qw, dim, l, &rw, 0);
            copy_pt(&mut qw, dim, k + r - j - s, &rw, p - j - s);
        }
        for i in (l + 1)..(k - s) {
            copy_pt(&mut qw, dim, i, &rw, i - l);
        }
        HSpline {
            p,
            knots: uq,
            pts: qw,
            dim,
        }
    }

    /// Inserts all knots of the sorted list `x` at once (NURBS Book A5.4,
    /// O((n + r) p dim)). Every `x_j` must lie in `[u_p, u_{m-p}]` and the resulting
    /// multiplicities must stay valid.
    pub fn refine(&self, x: &[f64]) -> HSpline {
        if x.is_empty() {
            return self.clone();
        }
        let (p, dim) = (self.p, self.dim);
        let u = &self.knots;
        let pw = &self.pts;
        let n = self.n_ctrl() - 1;
        let m = n + p + 1;
        let r = x.len() - 1;
        let a = crate::knots::find_span(u, p, x[0]);
        let b = crate::knots::find_span(u, p, x[r]) + 1;
        let mut qw = vec![0.0; (n + 1 + r + 1) * dim];
        let mut ubar = vec![0.0; m + 1 + r + 1];
        for j in 0..=(a - p) {
            copy_pt(&mut qw, dim, j, pw, j);
        }
        for j in (b - 1)..=n {
            copy_pt(&mut qw, dim, j + r + 1, pw, j);
        }
        ubar[..=a].copy_from_slice(&u[..=a]);
        for j in (b + p)..=m {
            ubar[j + r + 1] = u[j];
        }
        let mut i = b + p - 1;
        let mut k = b + p + r;
        for j in (0..=r).rev() {
            while x[j] <= u[i] && i > a {
                copy_pt(&mut qw, dim, k - p - 1, pw, i - p - 1);
                ubar[k] = u[i];
                k -= 1;
                i -= 1;
            }
            let src = qw[(k - p) * dim..(k - p + 1) * dim].to_vec();
            qw[(k - p - 1) * dim..(k - p) * dim].copy_from_slice(&src);
            for l in 1..=p {
                let ind = k - p + l;
                let alfa = ubar[k + l] - x[j];
                if alfa.abs() == 0.0 {
                    let src = qw[ind * dim..(ind + 1) * dim].to_vec();
                    qw[(ind - 1) * dim..ind * dim].copy_from_slice(&src);
                } else {
                    let alfa = alfa / (ubar[k + l] - u[i + l - p]);
                    blend_in(&mut qw, dim, ind - 1, ind, alfa);
                }
            }
            ubar[k] = x[j];
            k -= 1;
        }
        HSpline {
            p,
            knots: ubar,
            pts: qw,
            dim,
        }
    }

    /// Reversal with negated knots (`u ↦ -u`, exact in floating point).
    pub fn reverse_negated(&self) -> HSpline {
        let knots = self.knots.iter().rev().map(|k| -k).collect();
        let mut pts = Vec::with_capacity(self.pts.len());
        for chunk in self.pts.chunks_exact(self.dim).rev() {
            pts.extend_from_slice(chunk);
        }
        HSpline {
            p: self.p,
            knots,
            pts,
            dim: self.dim,
        }
    }

    /// Makes the left end clamped (first `p + 1` knots equal to the domain start) without
    /// changing the curve on its domain: inserts `u_p` up to multiplicity `p`, then drops
    /// the knots and control points left of the domain.
    fn clamp_left(&self) -> HSpline {
        let p = self.p;
        let a = self.knots[p];
        if self.knots[0] == a {
            return self.clone();
        }
        let s = self.knots.iter().filter(|&&x| x == a).count();
        let ins = self.insert(a, p.saturating_sub(s));
        let f = ins.knots.partition_point(|&k| k < a);
        let mut knots = vec![a];
        knots.extend_from_slice(&ins.knots[f..]);
        let pts = ins.pts[(f - 1) * self.dim..].to_vec();
        HSpline {
            p,
            knots,
            pts,
            dim: self.dim,
        }
    }

    /// Clamped representation of the same curve on the same domain.
    pub fn clamped(&self) -> HSpline {
        self.clamp_left()
            .reverse_negated()
            .clamp_left()
            .reverse_negated()
    }

    /// Raises the degree by `t` without changing the curve (NURBS Book A5.9,
    /// O((n + t s) p dim) with `s` distinct interior knots). Needs a clamped knot vector.
    /// Each distinct knot's multiplicity grows by `t`.
    #[allow(clippy::explicit_counter_loop)] // mirrors the book's first/last bookkeeping
    pub fn elevate(&self, t: usize) -> HSpline {
        if t == 0 {
            return self.clone();
        }
        let (p, dim) = (self.p, self.dim);
        let u = &self.knots;
        let pw = &self.pts;
        let n = self.n_ctrl() - 1;
        let m = n + p + 1;
        let ph = p + t;
        let ph2 = ph / 2;
        let distinct = 1 + u.windows(2).filter(|w| w[1] > w[0]).count();
        let max_ctrl = n + 1 + t * distinct;
        let mut qw = vec![0.0; max_ctrl * dim];
        let mut uh = vec![0.0; max_ctrl + ph + 1];
        // Bézier degree-elevation coefficients
        let mut bezalfs = vec![vec![0.0; p + 1]; ph + 1];
        bezalfs[0][0] = 1.0;
        bezalfs[ph][p] = 1.0;
        for i in 1..=ph2 {
            let inv = 1.0 / crate::util::binomial(ph, i);
            let mpi = p.min(i);
            for j in i.saturating_sub(t)..=mpi {
                bezalfs[i][j] = inv * crate::util::binomial(p, j) * crate::util::binomial(t, i - j);
            }
        }
        for i in (ph2 + 1)..ph {
            let mpi = p.min(i);
            for j in i.saturating_sub(t)..=mpi {
                bezalfs[i][j] = bezalfs[ph - i][p - j];
            }
        }
        let mut bpts = vec![0.0; (p + 1) * dim];
        let mut ebpts = vec![0.0; (ph + 1) * dim];
        let mut next_bpts = vec![0.0; p.max(1) * dim];
        let mut alfs = vec![0.0; p.max(1)];
        let mut mh = ph;
        let mut kind = ph + 1;
        let mut r: isize = -1;
        let mut a = p;
        let mut b = p + 1;
        let mut cind = 1usize;
        let mut ua = u[0];
        copy_pt(&mut qw, dim, 0, pw, 0);
        for k in uh.iter_mut().take(ph + 1) {
            *k = ua;
        }
        bpts.copy_from_slice(&pw[..(p + 1) * dim]);
        while b < m {
            let i0 = b;
            while b < m && u[b] == u[b + 1] {
                b += 1;
            }
            let mul = b - i0 + 1;
            mh += mul + t;
            let ub = u[b];
            let oldr = r;
            r = p as isize - mul as isize;
            let lbz = if oldr > 0 { (oldr as usize + 2) / 2 } else { 1 };
            let rbz = if r > 0 {
                ph - (r as usize).div_ceil(2)
            } else {
                ph
            };
            if r > 0 {
                // insert knot u(b) r times to get the Bézier segment
                let numer = ub - ua;
                for k in ((mul + 1)..=p).rev() {
                    alfs[k - mul - 1] = numer / (u[a + k] - ua);
                }
                let ru = r as usize;
                for j in 1..=ru {
                    let save = ru - j;
                    let s = mul + j;
                    for k in (s..=p).rev() {
                        blend_in(&mut bpts, dim, k, k - 1, alfs[k - s]);
                    }
                    copy_pt(&mut next_bpts, dim, save, &bpts, p);
                }
            }
            // degree-elevate the Bézier segment
            for i in lbz..=ph {
                let e = &mut ebpts[i * dim..(i + 1) * dim];
                e.iter_mut().for_each(|x| *x = 0.0);
                let mpi = p.min(i);
                for j in i.saturating_sub(t)..=mpi {
                    for c in 0..dim {
                        e[c] += bezalfs[i][j] * bpts[j * dim + c];
                    }
                }
            }
            if oldr > 1 {
                // remove knot u = ua (oldr - 1) times
                let oldr_u = oldr as usize;
                let mut first = kind as isize - 2;
                let mut last = kind as isize;
                let den = ub - ua;
                let bet = (ub - uh[kind - 1]) / den;
                for tr in 1..oldr_u {
                    let tr = tr as isize;
                    let mut i = first;
                    let mut j = last;
                    let mut kj = j - kind as isize + 1;
                    while j - i > tr {
                        if (i as usize) < cind {
                            let iu = i as usize;
                            let alf = (ub - uh[iu]) / (ua - uh[iu]);
                            blend_in(&mut qw, dim, iu, iu - 1, alf);
                        }
                        if j >= lbz as isize {
                            let kju = kj as usize;
                            let coef = if j - tr <= kind as isize - ph as isize + oldr {
                                (ub - uh[(j - tr) as usize]) / den
                            } else {
                                bet
                            };
                            blend_in(&mut ebpts, dim, kju, kju + 1, coef);
                        }
                        i += 1;
                        j -= 1;
                        kj -= 1;
                    }
                    first -= 1;
                    last += 1;
                }
            }
            if a != p {
                // load the knot ua
                for _ in 0..(ph as isize - oldr) {
                    uh[kind] = ua;
                    kind += 1;
                }
            }
            for j in lbz..=rbz {
                copy_pt(&mut qw, dim, cind, &ebpts, j);
                cind += 1;
            }
            if b < m {
                let ru = r.max(0) as usize;
                for j in 0..ru {
                    copy_pt(&mut bpts, dim, j, &next_bpts, j);
                }
                for j in ru..=p {
                    copy_pt(&mut bpts, dim, j, pw, b - p + j);
                }
                a = b;
                b += 1;
                ua = ub;
            } else {
                for i in 0..=ph {
                    uh[kind + i] = ub;
                }
            }
        }
        let nh = mh - ph - 1;
        qw.truncate((nh + 1) * dim);
        uh.truncate(nh + ph + 2);
        HSpline {
            p: ph,
            knots: uh,
            pts: qw,
            dim,
        }
    }

    /// Bézier decomposition by refinement: every interior break gets multiplicity `p`;
    /// returns the refined spline (segment `k` uses points `k p ..= k p + p`) and the break
    /// values including the domain ends. Needs a clamped knot vector.
    pub fn to_bezier(&self) -> (HSpline, Vec<f64>) {
        let p = self.p;
        let (a, b) = (self.knots[p], self.knots[self.knots.len() - 1 - p]);
        let mut x = Vec::new();
        let mut breaks = vec![a];
        let mut i = 0;
        let k = &self.knots;
        while i < k.len() {
            let v = k[i];
            let mut j = i;
            while j < k.len() && k[j] == v {
                j += 1;
            }
            if v > a && v < b {
                x.extend(std::iter::repeat_n(v, p - (j - i)));
                breaks.push(v);
            }
            i = j;
        }
        breaks.push(b);
        (self.refine(&x), breaks)
    }
}
