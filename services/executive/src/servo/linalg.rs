//! The small dense linear algebra pose refinement needs: solving, inverting and the sandwich
//! covariance of a 4x4 system. Written out rather than taken from a linear-algebra crate: these
//! are the only matrix operations the executive does, on 4x4 systems.

/// The size of the systems: pose refinement's unknowns `x, y, heading, pitch`.
pub const N: usize = 4;

/// A square matrix of the unknowns.
pub type Matrix = [[f64; N]; N];

/// `A x = b` by Gaussian elimination with partial pivoting; `None` when singular.
pub fn solve_n(mut a: Matrix, mut b: [f64; N]) -> Option<[f64; N]> {
    for col in 0..N {
        let pivot = (col..N).max_by(|&i, &j| a[i][col].abs().total_cmp(&a[j][col].abs()))?;
        if a[pivot][col].abs() < 1e-300 {
            return None;
        }
        a.swap(col, pivot);
        b.swap(col, pivot);
        let (top, below) = a.split_at_mut(col + 1);
        let pivot_row = top[col];
        for (k, row) in below.iter_mut().enumerate() {
            let f = row[col] / pivot_row[col];
            for (cell, &p) in row.iter_mut().zip(&pivot_row).skip(col) {
                *cell -= f * p;
            }
            b[col + 1 + k] -= f * b[col];
        }
    }
    let mut x = [0.0; N];
    for row in (0..N).rev() {
        let tail: f64 = (row + 1..N).map(|k| a[row][k] * x[k]).sum();
        x[row] = (b[row] - tail) / a[row][row];
    }
    Some(x)
}

/// `A⁻¹`, column by column; `None` when singular.
pub fn inverse(a: Matrix) -> Option<Matrix> {
    let mut inv = [[0.0; N]; N];
    for k in 0..N {
        let mut e = [0.0; N];
        e[k] = 1.0;
        let col = solve_n(a, e)?;
        for (row, &c) in inv.iter_mut().zip(&col) {
            row[k] = c;
        }
    }
    Some(inv)
}

/// `A⁻¹ B A⁻¹` (for symmetric `A`): the covariance of a least-squares estimate whose normal
/// matrix is `A` when its residuals' true spread gives `B`.
pub fn sandwich(a: Matrix, b: Matrix) -> Option<Matrix> {
    let inv = inverse(a)?;
    let product = |x: &Matrix, y: &Matrix| {
        let mut out = [[0.0; N]; N];
        for (r, row) in out.iter_mut().enumerate() {
            for (c, cell) in row.iter_mut().enumerate() {
                *cell = (0..N).map(|k| x[r][k] * y[k][c]).sum();
            }
        }
        out
    };
    Some(product(&product(&inv, &b), &inv))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_system_is_solved_inverted_and_sandwiched() {
        let a = [[4.0, 1.0, 0.0, 0.5], [1.0, 3.0, 0.2, 0.0], [0.0, 0.2, 2.0, 0.1], [0.5, 0.0, 0.1, 1.0]];
        let x = solve_n(a, [1.0, 2.0, 3.0, 4.0]).expect("regular");
        for (r, row) in a.iter().enumerate() {
            let ax: f64 = row.iter().zip(&x).map(|(p, q)| p * q).sum();
            assert!((ax - [1.0, 2.0, 3.0, 4.0][r]).abs() < 1e-12);
        }
        // With B = A, A⁻¹ B A⁻¹ is A⁻¹.
        let (inv, s) = (inverse(a).expect("regular"), sandwich(a, a).expect("regular"));
        assert!(inv.iter().flatten().zip(s.iter().flatten()).all(|(p, q)| (p - q).abs() < 1e-12));
        assert!(solve_n([[0.0; N]; N], [1.0; N]).is_none());
    }
}
