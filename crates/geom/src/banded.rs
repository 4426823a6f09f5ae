//! A banded linear solver for the spline fitters: collocation matrices (interpolation) and
//! normal equations (least squares) of B-splines are banded, so a fit of `n` points costs
//! `O(n·p²)` instead of a dense `O(n³)`.

// Index loops follow the textbook elimination so the band limits stay visible.
#![allow(clippy::needless_range_loop)]

use crate::curve::Vec3;
use crate::error::CurveError;

/// An `n × n` matrix with `kl` sub- and `ku` super-diagonals, stored row by row.
pub(crate) struct Banded {
    n: usize,
    kl: usize,
    ku: usize,
    a: Vec<f64>,
}

impl Banded {
    pub(crate) fn new(n: usize, kl: usize, ku: usize) -> Self {
        Banded {
            n,
            kl,
            ku,
            a: vec![0.0; n * (kl + ku + 1)],
        }
    }

    fn idx(&self, i: usize, j: usize) -> Option<usize> {
        (i < self.n && j < self.n && j + self.kl >= i && j <= i + self.ku)
            .then(|| i * (self.kl + self.ku + 1) + j + self.kl - i)
    }

    /// `A[i][j] += v`; entries outside the band are a caller bug and are ignored.
    pub(crate) fn add(&mut self, i: usize, j: usize, v: f64) {
        if let Some(k) = self.idx(i, j) {
            self.a[k] += v;
        }
    }

    fn get(&self, i: usize, j: usize) -> f64 {
        self.idx(i, j).map_or(0.0, |k| self.a[k])
    }

    /// Solve `A x = rhs` in place by Gaussian elimination without pivoting. That is stable for
    /// the matrices used here: B-spline collocation matrices are totally positive (de Boor &
    /// Pinkus 1977) and normal matrices are symmetric positive definite.
    pub(crate) fn solve(mut self, rhs: &mut [Vec3]) -> Result<(), CurveError> {
        let n = self.n;
        let scale = self.a.iter().fold(0.0f64, |m, v| m.max(v.abs()));
        let tiny = scale * 1e-14;
        for k in 0..n {
            let pivot = self.get(k, k);
            if pivot.is_nan() || pivot.abs() <= tiny {
                return Err(CurveError::Singular);
            }
            for i in k + 1..n.min(k + self.kl + 1) {
                let l = self.get(i, k) / pivot;
                if l == 0.0 {
                    continue;
                }
                for j in k..n.min(k + self.ku + 1) {
                    let v = self.get(k, j);
                    self.add(i, j, -l * v);
                }
                let rk = rhs[k];
                rhs[i] -= rk * l;
            }
        }
        for k in (0..n).rev() {
            let mut x = rhs[k];
            for j in k + 1..n.min(k + self.ku + 1) {
                x -= rhs[j] * self.get(k, j);
            }
            rhs[k] = x / self.get(k, k);
        }
        if rhs.iter().flat_map(|v| v.iter()).all(|c| c.is_finite()) {
            Ok(())
        } else {
            Err(CurveError::Singular)
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn tridiagonal() {
        // [2 1 0; 1 3 1; 0 1 4] x = b with x = (1, 2, 3).
        let mut m = Banded::new(3, 1, 1);
        for (i, j, v) in [
            (0, 0, 2.),
            (0, 1, 1.),
            (1, 0, 1.),
            (1, 1, 3.),
            (1, 2, 1.),
            (2, 1, 1.),
            (2, 2, 4.),
        ] {
            m.add(i, j, v);
        }
        let mut b = [
            Vec3::new(4., 0., 0.),
            Vec3::new(10., 0., 0.),
            Vec3::new(14., 0., 0.),
        ];
        m.solve(&mut b).unwrap();
        for (i, want) in [1.0, 2.0, 3.0].iter().enumerate() {
            assert!((b[i].x - want).abs() < 1e-14);
        }
        let m = Banded::new(2, 1, 1);
        assert_eq!(m.solve(&mut [Vec3::zeros(); 2]), Err(CurveError::Singular));
    }
}
