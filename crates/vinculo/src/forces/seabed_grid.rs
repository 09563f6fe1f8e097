//! A seabed of varying height: heights z_b on a rectangular grid of x and y ticks, bilinear in
//! each cell (MoorDyn's `SeafloorFile`, its 3D seafloor; `docs/theory/seabed-and-line-loads.md`).
//!
//! In the cell x_i <= x <= x_{i+1}, y_j <= y <= y_{j+1}, with fx = (x - x_i) / (x_{i+1} - x_i)
//! and fy = (y - y_j) / (y_{j+1} - y_j):
//!
//! ```text
//! z_b = (1 - fx)(1 - fy) z_ij + fx (1 - fy) z_i+1,j + (1 - fx) fy z_i,j+1 + fx fy z_i+1,j+1
//! dz_b/dx = ((1 - fy)(z_i+1,j - z_ij) + fy (z_i+1,j+1 - z_i,j+1)) / (x_{i+1} - x_i)
//! dz_b/dy = ((1 - fx)(z_i,j+1 - z_ij) + fx (z_i+1,j+1 - z_i+1,j)) / (y_{j+1} - y_j)
//! ```
//!
//! The surface is continuous; its slope jumps across the grid lines (the derivative used there
//! is the one of the cell on the far side, `x_i <= x < x_{i+1}`). Beyond the grid the height is
//! the one at its edge (a constant extension, no slope across the edge), as MoorDyn's
//! interpolation clamps there. A plane is reproduced exactly.

use crate::error::{Error, Result};

/// Heights of the seabed on a grid of x and y ticks (m), bilinear in each cell.
#[derive(Debug, Clone, PartialEq)]
pub struct SeabedGrid {
    x: Vec<f64>,
    y: Vec<f64>,
    /// z[i * ny + j]: the height at (x[i], y[j]).
    z: Vec<f64>,
}

/// The cell of `ticks` that holds `value` and the share of the way across it (0 outside, at
/// the nearest edge; a single tick is a cell of no extent).
#[inline]
fn locate(ticks: &[f64], value: f64) -> (usize, f64, f64) {
    let n = ticks.len();
    if n == 1 || value < ticks[0] {
        return (0, 0.0, 0.0);
    }
    if value >= ticks[n - 1] {
        return (n - 2, 1.0, 0.0);
    }
    // The last tick at or below the value: ticks[i] <= value < ticks[i + 1].
    let i = ticks.partition_point(|&t| t <= value) - 1;
    let width = ticks[i + 1] - ticks[i];
    (i, (value - ticks[i]) / width, 1.0 / width)
}

impl SeabedGrid {
    /// A grid of `x.len()` by `y.len()` heights `z` (x-major: `z[i * y.len() + j]` at
    /// `(x[i], y[j])`).
    ///
    /// # Errors
    /// [`Error::InvalidParameter`] when a tick list is empty, not finite or not strictly
    /// increasing, when `z` does not hold one height a grid point, or when a height is not
    /// finite.
    pub fn new(x: Vec<f64>, y: Vec<f64>, z: Vec<f64>) -> Result<SeabedGrid> {
        for (name, ticks) in [("x", &x), ("y", &y)] {
            if ticks.is_empty() {
                return Err(Error::InvalidParameter {
                    name: format!("seabed grid {name} ticks"),
                    value: 0.0,
                    expected: "at least one tick".into(),
                });
            }
            if let Some(bad) = ticks.iter().find(|t| !t.is_finite()) {
                return Err(Error::InvalidParameter {
                    name: format!("seabed grid {name} ticks"),
                    value: *bad,
                    expected: "finite ticks".into(),
                });
            }
            for (k, pair) in ticks.windows(2).enumerate() {
                if pair[1] <= pair[0] {
                    return Err(Error::InvalidParameter {
                        name: format!("seabed grid {name} tick {}", k + 2),
                        value: pair[1],
                        expected: format!("above the tick before it, {}", pair[0]),
                    });
                }
            }
        }
        if z.len() != x.len() * y.len() {
            return Err(Error::InvalidParameter {
                name: "seabed grid heights".into(),
                value: z.len() as f64,
                expected: format!("{} x {} = {} heights", x.len(), y.len(), x.len() * y.len()),
            });
        }
        if let Some(k) = z.iter().position(|h| !h.is_finite()) {
            return Err(Error::InvalidParameter {
                name: format!(
                    "seabed grid height at x = {}, y = {}",
                    x[k / y.len()],
                    y[k % y.len()]
                ),
                value: z[k],
                expected: "a finite height (m)".into(),
            });
        }
        Ok(SeabedGrid { x, y, z })
    }

    /// The x ticks (m).
    pub fn x(&self) -> &[f64] {
        &self.x
    }

    /// The y ticks (m).
    pub fn y(&self) -> &[f64] {
        &self.y
    }

    /// The heights, x-major (m).
    pub fn heights(&self) -> &[f64] {
        &self.z
    }

    /// The height z_b at (x, y) and its slopes dz_b/dx, dz_b/dy (module documentation).
    #[inline]
    pub fn height_and_slope(&self, x: f64, y: f64) -> (f64, f64, f64) {
        let ny = self.y.len();
        let (i, fx, dfx) = locate(&self.x, x);
        let (j, fy, dfy) = locate(&self.y, y);
        let at = |a: usize, b: usize| self.z[a * ny + b];
        let (i1, j1) = ((i + 1).min(self.x.len() - 1), (j + 1).min(ny - 1));
        let (z00, z10, z01, z11) = (at(i, j), at(i1, j), at(i, j1), at(i1, j1));
        let height = (1.0 - fx) * (1.0 - fy) * z00
            + fx * (1.0 - fy) * z10
            + (1.0 - fx) * fy * z01
            + fx * fy * z11;
        let dx = ((1.0 - fy) * (z10 - z00) + fy * (z11 - z01)) * dfx;
        let dy = ((1.0 - fx) * (z01 - z00) + fx * (z11 - z10)) * dfy;
        (height, dx, dy)
    }

    /// The height z_b at (x, y) (m).
    #[inline]
    pub fn height(&self, x: f64, y: f64) -> f64 {
        self.height_and_slope(x, y).0
    }

    /// The mean of the grid's heights (m): MoorDyn's average depth is minus it.
    pub fn mean_height(&self) -> f64 {
        self.z.iter().sum::<f64>() / self.z.len() as f64
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A plane z = -50 + 0.2 x - 0.1 y on an uneven grid.
    fn plane() -> SeabedGrid {
        let x = vec![-100.0, -20.0, 0.0, 35.0, 200.0];
        let y = vec![-10.0, 5.0, 40.0];
        let z = x
            .iter()
            .flat_map(|&a| y.iter().map(move |&b| -50.0 + 0.2 * a - 0.1 * b))
            .collect();
        SeabedGrid::new(x, y, z).unwrap()
    }

    /// Bilinear interpolation reproduces a plane exactly inside the grid, with its slopes, and
    /// holds the edge's height (no slope) beyond it.
    #[test]
    fn a_plane_is_reproduced_and_clamped_at_the_edges() {
        let g = plane();
        for (x, y) in [
            (-99.0, -9.0),
            (-20.0, 5.0),
            (17.3, 22.2),
            (199.9, 39.9),
            (0.0, -10.0),
        ] {
            let (h, dx, dy) = g.height_and_slope(x, y);
            let exact = -50.0 + 0.2 * x - 0.1 * y;
            assert!((h - exact).abs() < 1e-12, "{h} vs {exact} at {x}, {y}");
            assert!(
                (dx - 0.2).abs() < 1e-12 && (dy + 0.1).abs() < 1e-12,
                "{dx} {dy}"
            );
        }
        // Beyond x = 200 (and y = 40): the height at the edge, no slope across it.
        let (h, dx, dy) = g.height_and_slope(250.0, 50.0);
        assert!((h - (-50.0 + 40.0 - 4.0)).abs() < 1e-12, "{h}");
        assert_eq!((dx, dy), (0.0, 0.0));
        let (h, dx, _) = g.height_and_slope(-150.0, 0.0);
        assert!((h - (-50.0 - 20.0)).abs() < 1e-12 && dx == 0.0, "{h} {dx}");
    }

    /// On a curved (bilinear, twisted) cell the slopes are the height's central differences.
    #[test]
    fn slopes_match_finite_differences() {
        let z = vec![-40.0, -42.0, -38.5, -45.0, -41.0, -39.0];
        let g = SeabedGrid::new(vec![0.0, 10.0, 25.0], vec![-5.0, 5.0], z).unwrap();
        let e = 1e-6;
        for (x, y) in [(3.0, -2.0), (17.0, 4.0), (24.0, -4.9)] {
            let (_, dx, dy) = g.height_and_slope(x, y);
            let fdx = (g.height(x + e, y) - g.height(x - e, y)) / (2.0 * e);
            let fdy = (g.height(x, y + e) - g.height(x, y - e)) / (2.0 * e);
            assert!(
                (dx - fdx).abs() < 1e-8 && (dy - fdy).abs() < 1e-8,
                "{dx} {fdx} {dy} {fdy}"
            );
        }
        // At the grid points, the given heights.
        assert_eq!(g.height(10.0, 5.0), -45.0);
        assert_eq!(g.height(25.0, -5.0), -41.0);
    }

    /// A single tick in y: the seabed varies along x alone.
    #[test]
    fn one_tick_makes_the_seabed_uniform_that_way() {
        let g = SeabedGrid::new(vec![0.0, 100.0], vec![0.0], vec![-50.0, -30.0]).unwrap();
        let (h, dx, dy) = g.height_and_slope(25.0, 1e3);
        assert!((h + 45.0).abs() < 1e-12 && (dx - 0.2).abs() < 1e-15 && dy == 0.0);
    }

    /// Unsorted ticks, a wrong number of heights and a NaN height are refused, named.
    #[test]
    fn bad_grids_are_refused() {
        let e = SeabedGrid::new(vec![0.0, 0.0], vec![0.0], vec![1.0, 2.0]).unwrap_err();
        assert!(e.to_string().contains("x tick 2"), "{e}");
        let e = SeabedGrid::new(vec![0.0, 1.0], vec![0.0, 1.0], vec![1.0; 3]).unwrap_err();
        assert!(e.to_string().contains("2 x 2 = 4"), "{e}");
        let e = SeabedGrid::new(vec![0.0], vec![0.0, 1.0], vec![1.0, f64::NAN]).unwrap_err();
        assert!(e.to_string().contains("x = 0, y = 1"), "{e}");
        assert!(SeabedGrid::new(vec![], vec![0.0], vec![]).is_err());
    }
}
