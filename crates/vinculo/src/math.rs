//! Small fixed-size vector and matrix helpers for 3D particle kinematics.

/// A 3-vector.
pub type Vec3 = [f64; 3];
/// A 3x3 matrix, row-major.
pub type Mat3 = [[f64; 3]; 3];

/// The zero 3x3 matrix.
pub const ZERO3: Mat3 = [[0.0; 3]; 3];

/// a - b
#[inline]
pub fn sub(a: Vec3, b: Vec3) -> Vec3 {
    [a[0] - b[0], a[1] - b[1], a[2] - b[2]]
}

/// a + b
#[inline]
pub fn add(a: Vec3, b: Vec3) -> Vec3 {
    [a[0] + b[0], a[1] + b[1], a[2] + b[2]]
}

/// s a
#[inline]
pub fn scale(s: f64, a: Vec3) -> Vec3 {
    [s * a[0], s * a[1], s * a[2]]
}

/// a . b
#[inline]
pub fn dot(a: Vec3, b: Vec3) -> f64 {
    a[0] * b[0] + a[1] * b[1] + a[2] * b[2]
}

/// The cross product a x b.
#[inline(always)]
pub fn cross(a: Vec3, b: Vec3) -> Vec3 {
    [
        a[1] * b[2] - a[2] * b[1],
        a[2] * b[0] - a[0] * b[2],
        a[0] * b[1] - a[1] * b[0],
    ]
}

/// |a|
#[inline]
pub fn norm(a: Vec3) -> f64 {
    dot(a, a).sqrt()
}

/// s I
#[inline]
pub fn diag(s: f64) -> Mat3 {
    [[s, 0.0, 0.0], [0.0, s, 0.0], [0.0, 0.0, s]]
}

/// s a b^T
#[inline]
pub fn outer(s: f64, a: Vec3, b: Vec3) -> Mat3 {
    let mut m = ZERO3;
    for (r, row) in m.iter_mut().enumerate() {
        for (c, x) in row.iter_mut().enumerate() {
            *x = s * a[r] * b[c];
        }
    }
    m
}

/// a + b (matrices)
#[inline]
pub fn add_mat(a: Mat3, b: Mat3) -> Mat3 {
    let mut m = a;
    for r in 0..3 {
        for c in 0..3 {
            m[r][c] += b[r][c];
        }
    }
    m
}

/// s a (matrix)
#[inline]
pub fn scale_mat(s: f64, a: Mat3) -> Mat3 {
    let mut m = a;
    for row in m.iter_mut() {
        for x in row.iter_mut() {
            *x *= s;
        }
    }
    m
}

/// true when every component is finite
#[inline]
pub fn is_finite(a: Vec3) -> bool {
    a.iter().all(|x| x.is_finite())
}

/// The norm of two parts from their infinity norms: the larger, NaN if either is.
pub fn larger_norm(a: f64, b: f64) -> f64 {
    if a.is_nan() || b.is_nan() {
        f64::NAN
    } else {
        a.max(b)
    }
}

/// The infinity norm of values taken one at a time, in four lanes (four independent running
/// maxima and a NaN flag, with no early exit) so that a pass that takes four consecutive
/// values a lane each turns into vector instructions: Newton's norms, the tree elimination's
/// solve as it writes its result, the distance of an iterate from a kept matrix's point.
#[derive(Debug, Clone, Copy, Default)]
pub struct LargestMagnitude {
    lanes: [f64; 4],
    nan: bool,
}

impl LargestMagnitude {
    /// Takes `x` into lane `lane` (0 to 3).
    #[inline(always)]
    pub fn take(&mut self, lane: usize, x: f64) {
        let a = x.abs();
        let m = &mut self.lanes[lane];
        *m = if a > *m { a } else { *m };
        self.nan |= a.is_nan();
    }

    /// The largest magnitude taken, NaN if a value was NaN.
    pub fn norm(&self) -> f64 {
        let m = &self.lanes;
        if self.nan {
            f64::NAN
        } else {
            m[0].max(m[1]).max(m[2].max(m[3]))
        }
    }
}
