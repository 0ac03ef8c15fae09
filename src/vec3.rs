//! Small-vector arithmetic on plain `[f64; 3]` points and directions, the one
//! home of these helpers for mesh, fem and contact. The operation order of
//! each function is fixed (results are compared bit for bit in tests); the
//! dual-number versions the contact kernel differentiates are generic
//! counterparts in `contact::autodiff`.

pub type Vec3 = [f64; 3];

pub fn add(a: Vec3, b: Vec3) -> Vec3 {
    [a[0] + b[0], a[1] + b[1], a[2] + b[2]]
}

pub fn sub(a: Vec3, b: Vec3) -> Vec3 {
    [a[0] - b[0], a[1] - b[1], a[2] - b[2]]
}

pub fn scale(a: Vec3, s: f64) -> Vec3 {
    [a[0] * s, a[1] * s, a[2] * s]
}

pub fn dot(a: Vec3, b: Vec3) -> f64 {
    a[0] * b[0] + a[1] * b[1] + a[2] * b[2]
}

pub fn cross(a: Vec3, b: Vec3) -> Vec3 {
    [
        a[1] * b[2] - a[2] * b[1],
        a[2] * b[0] - a[0] * b[2],
        a[0] * b[1] - a[1] * b[0],
    ]
}

/// Euclidean length.
pub fn norm(a: Vec3) -> f64 {
    dot(a, a).sqrt()
}

/// Determinant of the matrix with columns `a`, `b`, `c`.
pub fn triple(a: Vec3, b: Vec3, c: Vec3) -> f64 {
    dot(cross(a, b), c)
}

/// Squared distance between two points.
pub fn distance2(a: Vec3, b: Vec3) -> f64 {
    let d = sub(a, b);
    dot(d, d)
}

pub fn distance(a: Vec3, b: Vec3) -> f64 {
    distance2(a, b).sqrt()
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn products_of_the_unit_axes() {
        let (x, y, z) = ([1.0, 0.0, 0.0], [0.0, 1.0, 0.0], [0.0, 0.0, 1.0]);
        assert_eq!(cross(x, y), z);
        assert_eq!(cross(y, z), x);
        assert_eq!(cross(z, x), y);
        assert_eq!(dot(x, y), 0.0);
        assert_eq!(triple(x, y, z), 1.0);
        assert_eq!(triple(y, x, z), -1.0);
    }

    #[test]
    fn lengths_and_distances() {
        let a = [1.0, 2.0, 2.0];
        assert_eq!(norm(a), 3.0);
        assert_eq!(distance([4.0, 6.0, 2.0], [1.0, 2.0, 2.0]), 5.0);
        assert_eq!(distance2(a, [0.0; 3]), 9.0);
        assert_eq!(add(a, scale(a, -1.0)), [0.0; 3]);
        assert_eq!(sub(a, a), [0.0; 3]);
    }
}
