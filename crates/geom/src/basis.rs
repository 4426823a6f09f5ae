//! B-spline basis functions (Piegl & Tiller, *The NURBS Book*, ch. 2): span search A2.1,
//! non-zero basis functions A2.2 and their derivatives A2.3. The kernel under [`crate::nurbs`]
//! and the spline fitters; fixed-size stack arrays keep evaluation allocation-free.

// Index loops mirror the book's pseudo-code, so the code can be checked against it line by line.
#![allow(clippy::needless_range_loop)]

/// Highest supported degree; arrays below are sized for it. Controllers use degree ≤ 5.
pub const MAX_DEGREE: usize = 15;
/// Array width: basis functions of one span (`degree + 1`).
pub(crate) const W: usize = MAX_DEGREE + 1;
/// Highest derivative computed.
pub(crate) const MAX_DER: usize = 3;

/// A2.1 FindSpan: the index `i` with `knots[i] <= u < knots[i + 1]` among the spans
/// `first..=last` (the domain's non-empty spans). Values at or past either end map to the end
/// span, so the right end of the domain is closed.
pub fn find_span(knots: &[f64], first: usize, last: usize, u: f64) -> usize {
    if u >= knots[last + 1] {
        return last;
    }
    if u <= knots[first] {
        return first;
    }
    let (mut low, mut high) = (first, last + 1);
    let mut mid = (low + high) / 2;
    // Invariant knots[low] <= u < knots[high]; NaN never reaches here (callers clamp).
    while u < knots[mid] || u >= knots[mid + 1] {
        if u < knots[mid] {
            high = mid;
        } else {
            low = mid;
        }
        let next = (low + high) / 2;
        if next == mid {
            break;
        }
        mid = next;
    }
    mid
}

/// A2.2 BasisFuns: `n[j] = N_{span-p+j, p}(u)` for `j = 0..=p`.
pub fn basis_funs(knots: &[f64], span: usize, u: f64, p: usize, n: &mut [f64; W]) {
    // Scratch sized to the degree, as in ders_basis_funs: zeroing two 16-wide arrays per call
    // was a third of a cubic's cost (the least-squares fitter calls this once per data point).
    match p {
        0..=3 => basis_impl::<4>(knots, span, u, p, n),
        4..=5 => basis_impl::<6>(knots, span, u, p, n),
        _ => basis_impl::<W>(knots, span, u, p, n),
    }
}

fn basis_impl<const N: usize>(knots: &[f64], span: usize, u: f64, p: usize, n: &mut [f64; W]) {
    let mut left = [0.0; N];
    let mut right = [0.0; N];
    n[0] = 1.0;
    for j in 1..=p {
        left[j] = u - knots[span + 1 - j];
        right[j] = knots[span + j] - u;
        let mut saved = 0.0;
        for r in 0..j {
            // The denominator is a knot difference across the span: > 0 for a non-empty span.
            let temp = n[r] / (right[r + 1] + left[j - r]);
            n[r] = saved + right[r + 1] * temp;
            saved = left[j - r] * temp;
        }
        n[j] = saved;
    }
}

/// A2.3 DersBasisFuns: `ders[k][j]` = k-th derivative of `N_{span-p+j, p}` at `u`, for
/// `k = 0..=nd` (`nd <= MAX_DER`); derivatives above the degree are zero.
pub fn ders_basis_funs(
    knots: &[f64],
    span: usize,
    u: f64,
    p: usize,
    nd: usize,
    ders: &mut [[f64; W]; MAX_DER + 1],
) {
    // Scratch arrays sized to the degree: zeroing a 16×16 table costs more than the
    // arithmetic of a cubic, and controllers use degree ≤ 5.
    match p {
        0..=3 => ders_impl::<4>(knots, span, u, p, nd, ders),
        4..=5 => ders_impl::<6>(knots, span, u, p, nd, ders),
        _ => ders_impl::<W>(knots, span, u, p, nd, ders),
    }
}

fn ders_impl<const N: usize>(
    knots: &[f64],
    span: usize,
    u: f64,
    p: usize,
    nd: usize,
    ders: &mut [[f64; W]; MAX_DER + 1],
) {
    let mut ndu = [[0.0; N]; N];
    let mut left = [0.0; N];
    let mut right = [0.0; N];
    ndu[0][0] = 1.0;
    for j in 1..=p {
        left[j] = u - knots[span + 1 - j];
        right[j] = knots[span + j] - u;
        let mut saved = 0.0;
        for r in 0..j {
            // Lower triangle keeps the knot differences, upper the basis functions.
            ndu[j][r] = right[r + 1] + left[j - r];
            let temp = ndu[r][j - 1] / ndu[j][r];
            ndu[r][j] = saved + right[r + 1] * temp;
            saved = left[j - r] * temp;
        }
        ndu[j][j] = saved;
    }
    for row in ders.iter_mut() {
        row[..=p].fill(0.0);
    }
    for j in 0..=p {
        ders[0][j] = ndu[j][p];
    }
    let nd = nd.min(p).min(MAX_DER);
    let mut a = [[0.0; N]; 2];
    let pi = p as isize;
    for r in 0..=pi {
        let (mut s1, mut s2) = (0usize, 1usize);
        a[0][0] = 1.0;
        for k in 1..=nd as isize {
            let mut d = 0.0;
            let rk = r - k;
            let pk = pi - k;
            if r >= k {
                a[s2][0] = a[s1][0] / ndu[(pk + 1) as usize][rk as usize];
                d = a[s2][0] * ndu[rk as usize][pk as usize];
            }
            let j1 = if rk >= -1 { 1 } else { -rk };
            let j2 = if r - 1 <= pk { k - 1 } else { pi - r };
            for j in j1..=j2 {
                let (ju, rkj) = (j as usize, (rk + j) as usize);
                a[s2][ju] = (a[s1][ju] - a[s1][ju - 1]) / ndu[(pk + 1) as usize][rkj];
                d += a[s2][ju] * ndu[rkj][pk as usize];
            }
            if r <= pk {
                let (ku, ru) = (k as usize, r as usize);
                a[s2][ku] = -a[s1][ku - 1] / ndu[(pk + 1) as usize][ru];
                d += a[s2][ku] * ndu[ru][pk as usize];
            }
            ders[k as usize][r as usize] = d;
            std::mem::swap(&mut s1, &mut s2);
        }
    }
    // Multiply through by p!/(p-k)!.
    let mut f = p as f64;
    for k in 1..=nd {
        for v in ders[k][..=p].iter_mut() {
            *v *= f;
        }
        f *= (p - k) as f64;
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn partition_of_unity_and_derivative_sum_zero() {
        let knots = [0.0, 0.0, 0.0, 0.0, 1.0, 2.0, 3.0, 3.0, 3.0, 3.0];
        for &u in &[0.0, 0.3, 1.0, 1.7, 2.999, 3.0] {
            let span = find_span(&knots, 3, 5, u);
            let mut d = [[0.0; W]; MAX_DER + 1];
            ders_basis_funs(&knots, span, u, 3, 3, &mut d);
            let mut n = [0.0; W];
            basis_funs(&knots, span, u, 3, &mut n);
            assert!((d[0][..4].iter().sum::<f64>() - 1.0).abs() < 1e-14);
            for k in 1..=3 {
                assert!(d[k][..4].iter().sum::<f64>().abs() < 1e-12, "k={k} u={u}");
            }
            for j in 0..4 {
                assert!((n[j] - d[0][j]).abs() < 1e-15);
            }
        }
    }

    #[test]
    fn span_search_closes_right_end_and_skips_empty_spans() {
        let knots = [0.0, 0.0, 0.0, 1.0, 1.0, 2.0, 2.0, 2.0];
        assert_eq!(find_span(&knots, 2, 4, 2.0), 4);
        assert_eq!(find_span(&knots, 2, 4, 1.0), 4);
        assert_eq!(find_span(&knots, 2, 4, 0.999), 2);
        assert_eq!(find_span(&knots, 2, 4, -5.0), 2);
    }
}
