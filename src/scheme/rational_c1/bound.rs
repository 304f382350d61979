//! Lemma 2.3: lower bounds on the free parameter that make the minimal zero of a shooting
//! cubic simple.
//!
//! A shooting cubic is P(t) + b·D(t) with P = Σ p_s B³_s(t) (p_0 < 0) and D = d_2 B³_2 + d_3 B³_3
//! (the part that grows with the free parameter b). Subdividing at t* ∈ (0, 1], the Bernstein
//! coefficients over [0, t*] are P_k(t*) + b·D_k(t*) (P_k, D_k: de Casteljau values of order k).
//! With p_0 < 0 there is exactly one sign change — hence exactly one, simple, zero in [0, t*],
//! which is then the minimal zero — when the last coefficient is positive and either the third
//! one is positive (first case of the lemma) or the second one is ≤ 0 (second case). The
//! threshold is therefore the infimum over t* of
//!   max(−P_2/D_2, −P_3/D_3)              (first case),
//!   −P_3/D_3 where P_1(t*) ≤ 0           (second case).
//! For a face, D = t² (d_2 = 1/3, d_3 = 1), which is the paper's β = 1.
//!
//! Accuracy: any t* gives a sufficient threshold, so minimising over a sample of t* can only
//! overestimate the exact b_min (the safe side). We sample [`T_SAMPLES`] values and refine the
//! best one by 12 golden-section steps (bracket 2/16 → ~0.7e-3 in t*); the result is within
//! ~1e-5 (relative to the coefficient scale) of the exact infimum for smooth thresholds, and
//! never below it.

/// Samples of t* in (0, 1].
pub const T_SAMPLES: usize = 16;

#[inline]
fn casteljau(p: [f64; 4], t: f64) -> [f64; 4] {
    let s = 1.0 - t;
    let p1 = p[0] * s + p[1] * t;
    let q1 = p[1] * s + p[2] * t;
    let r1 = p[2] * s + p[3] * t;
    let p2 = p1 * s + q1 * t;
    let q2 = q1 * s + r1 * t;
    [p[0], p1, p2, p2 * s + q2 * t]
}

/// The threshold at one t*: b must exceed it (∞ when t* gives no condition).
#[inline]
#[must_use]
pub fn threshold_at(p: [f64; 4], d: [f64; 4], t: f64) -> f64 {
    let pk = casteljau(p, t);
    let dk = casteljau(d, t);
    if dk[3] <= 0.0 {
        return f64::INFINITY;
    }
    let last = -pk[3] / dk[3];
    let mut best = f64::INFINITY;
    if dk[2] > 0.0 {
        best = last.max(-pk[2] / dk[2]);
    }
    if pk[1] <= 0.0 {
        best = best.min(last);
    }
    best
}

/// b_min of Lemma 2.3 for the shooting cubic with coefficients `p` plus b·`d` (d_0 = d_1 = 0),
/// from above (see the module docs). Returns −∞ when the lemma puts no condition on b: p_0 > 0
/// (this side is not used at this point) or p_0 = 0 with p_1 ≠ 0 (the zero t = 0 is simple).
/// Returns +∞ when no b works.
#[must_use]
pub fn lemma_bound(p: [f64; 4], d: [f64; 4]) -> f64 {
    lemma_bound_arg(p, d).0
}

/// Whether the lemma puts no condition on b at this shooting line (see [`lemma_bound`]).
#[inline]
fn unconditioned(p: [f64; 4]) -> bool {
    let scale = p.iter().map(|x| x.abs()).fold(0.0, f64::max).max(1e-300);
    p[0] > 1e-13 * scale || (p[0] >= -1e-13 * scale && p[1].abs() > 1e-9 * scale)
}

/// The largest [`lemma_bound`] over many shooting lines, never below `floor`. Each line is
/// first tested at the t* that was best for the previous line, then at the coarse samples of
/// t*: as soon as one threshold does not exceed the running maximum, the line cannot raise it
/// (any t* gives a sufficient threshold, and the line's bound is the smallest of them), so
/// most lines cost one or a few evaluations and only the lines that do raise the maximum are
/// refined.
#[must_use]
pub fn max_lemma_bound(lines: impl Iterator<Item = ([f64; 4], [f64; 4])>, floor: f64) -> f64 {
    let mut best = floor;
    let mut hint = 0.5;
    for (p, d) in lines {
        if unconditioned(p) || threshold_at(p, d, hint) <= best {
            continue;
        }
        if let Some(t) = (1..=T_SAMPLES)
            .map(|k| k as f64 / T_SAMPLES as f64)
            .find(|&t| threshold_at(p, d, t) <= best)
        {
            hint = t;
            continue;
        }
        let (v, t) = lemma_bound_arg(p, d);
        if v > best {
            best = v;
        }
        hint = t;
    }
    best
}

/// [`lemma_bound`] and the t* where it was attained.
#[must_use]
pub fn lemma_bound_arg(p: [f64; 4], d: [f64; 4]) -> (f64, f64) {
    if unconditioned(p) {
        return (f64::NEG_INFINITY, 0.5);
    }
    let mut best = f64::INFINITY;
    let mut best_k = 0;
    for k in 1..=T_SAMPLES {
        let v = threshold_at(p, d, k as f64 / T_SAMPLES as f64);
        if v < best {
            best = v;
            best_k = k;
        }
    }
    if !best.is_finite() {
        return (best, 0.5);
    }
    // Golden-section refinement around the best sample.
    let h = 1.0 / T_SAMPLES as f64;
    let (mut lo, mut hi) = (
        (best_k as f64 - 1.0) * h,
        ((best_k as f64 + 1.0) * h).min(1.0),
    );
    lo = lo.max(1e-9);
    let g = 0.618_033_988_749_894_9;
    let mut x1 = hi - g * (hi - lo);
    let mut x2 = lo + g * (hi - lo);
    let mut f1 = threshold_at(p, d, x1);
    let mut f2 = threshold_at(p, d, x2);
    for _ in 0..12 {
        if f1 < f2 {
            hi = x2;
            x2 = x1;
            f2 = f1;
            x1 = hi - g * (hi - lo);
            f1 = threshold_at(p, d, x1);
        } else {
            lo = x1;
            x1 = x2;
            f1 = f2;
            x2 = lo + g * (hi - lo);
            f2 = threshold_at(p, d, x2);
        }
    }
    let h = best_k as f64 / T_SAMPLES as f64;
    if f1 <= f2 && f1 < best {
        (f1, x1)
    } else if f2 < best {
        (f2, x2)
    } else {
        (best, h)
    }
}

/// Whether the minimal zero in [0, 1] of the cubic with Bernstein coefficients `c` is simple
/// (checked by dense sampling and bisection; for tests and reports). Returns None when there
/// is no zero in [0, 1), Some(|P'(t)| / coefficient scale) at the minimal zero otherwise.
#[must_use]
pub fn minimal_root_slope(c: [f64; 4]) -> Option<(f64, f64)> {
    let scale = c.iter().map(|x| x.abs()).fold(0.0, f64::max).max(1e-300);
    let f = |t: f64| casteljau(c, t)[3];
    let df = |t: f64| {
        let s = 1.0 - t;
        3.0 * ((c[1] - c[0]) * s * s + 2.0 * (c[2] - c[1]) * s * t + (c[3] - c[2]) * t * t)
    };
    if c[0] == 0.0 {
        return Some((0.0, df(0.0).abs() / scale));
    }
    let n = 2000;
    let mut prev = f(0.0);
    for k in 1..=n {
        let t = k as f64 / n as f64;
        let v = f(t);
        if v == 0.0 || v.signum() != prev.signum() {
            let (mut a, mut b) = ((k - 1) as f64 / n as f64, t);
            for _ in 0..60 {
                let m = 0.5 * (a + b);
                if f(m).signum() == prev.signum() && f(m) != 0.0 {
                    a = m;
                } else {
                    b = m;
                }
            }
            let r = 0.5 * (a + b);
            return Some((r, df(r).abs() / scale));
        }
        prev = v;
    }
    None
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn bound_is_sufficient_and_nearly_sharp() {
        // A cubic dipping twice: for b just above the bound the minimal root is simple.
        let cases = [
            [-1.0, 2.0, -3.0, 0.0],
            [-0.5, -0.2, -1.0, 0.0],
            [-2.0, 1.0, 1.0, 0.0],
            [-1.0, 3.0, -6.0, 0.0],
        ];
        let d = [0.0, 0.0, 1.0 / 3.0, 1.0];
        for p in cases {
            let b = lemma_bound(p, d);
            assert!(b.is_finite());
            for extra in [1e-2, 1.0, 100.0] {
                let c = [
                    p[0],
                    p[1],
                    p[2] + (b + extra) * d[2],
                    p[3] + (b + extra) * d[3],
                ];
                let (_, slope) = minimal_root_slope(c)
                    .unwrap_or_else(|| panic!("no root: p={p:?} b={b} extra={extra} c={c:?}"));
                assert!(slope > 0.0, "p={p:?} b={b} extra={extra}");
            }
        }
    }

    /// The pruned maximum is never above the plain maximum of [`lemma_bound`] (pruning only
    /// skips lines that some t* already satisfies) and it is sufficient: just above it, every
    /// line's minimal zero is simple. Seeded random lines.
    #[test]
    fn pruned_max_is_sufficient() {
        let mut state = 0x9e37_79b9_7f4a_7c15_u64;
        let mut rnd = move || {
            state ^= state << 13;
            state ^= state >> 7;
            state ^= state << 17;
            (state >> 11) as f64 / (1u64 << 53) as f64 * 2.0 - 1.0
        };
        for _ in 0..100 {
            let lines: Vec<([f64; 4], [f64; 4])> = (0..40)
                .map(|_| {
                    let p = [-rnd().abs() - 0.01, rnd(), rnd(), rnd()];
                    let d = [0.0, 0.0, 0.5 * rnd().abs() + 0.1, rnd().abs() + 0.1];
                    (p, d)
                })
                .collect();
            let plain = lines
                .iter()
                .map(|&(p, d)| lemma_bound(p, d))
                .fold(-1.0, f64::max);
            let pruned = max_lemma_bound(lines.iter().copied(), -1.0);
            assert!(pruned <= plain, "{pruned} > {plain}");
            // 1e-2 above the bound (coefficients are O(1)): where P dips below 0 again before
            // t = 1, the positive stretch after the minimal zero is then wide enough for the
            // 2000-sample root finder to see.
            let b = pruned + 1e-2;
            for (p, d) in &lines {
                let c = std::array::from_fn(|k| p[k] + b * d[k]);
                let Some((_, slope)) = minimal_root_slope(c) else {
                    panic!("no zero p={p:?} d={d:?} b={b} plain={plain}")
                };
                assert!(slope > 0.0, "p={p:?} d={d:?} b={b}");
            }
        }
    }

    #[test]
    fn nonnegative_start_is_free() {
        let d = [0.0, 0.0, 1.0 / 3.0, 1.0];
        assert_eq!(lemma_bound([1.0, -1.0, 0.0, 0.0], d), f64::NEG_INFINITY);
        assert_eq!(lemma_bound([0.0, 1.0, -5.0, 0.0], d), f64::NEG_INFINITY);
    }
}
