//! The primitive shapes, in their own local frame: centred on the origin, axis along z.
//!
//! Each shape has two functions:
//! - [`Shape::contains`], the exact point predicate that defines the solid (a voxel is
//!   black exactly when this holds at its centre);
//! - [`Shape::bound`], a *1-Lipschitz* function with the same sign (negative inside,
//!   positive outside): `|bound(p)|` never exceeds the distance from `p` to the
//!   surface. A ball of radius `R` around `p` therefore lies wholly inside when
//!   `bound(p) < -R` and wholly outside when `bound(p) > R`; this is the
//!   bounding-sphere cell test of the classifier.
//!
//! Where the exact distance is cheap (sphere, box, torus, capsule) it is used; for the
//! ellipsoid, the elliptic cylinder and the elliptic cone a scaled implicit function
//! divided by its Lipschitz constant is used instead, still a valid lower bound.

/// A primitive solid in its local frame (centred on the origin, axis along z).
///
/// ```
/// use tesseral::csg::Shape;
/// let s = Shape::sphere(2.0);
/// assert!(s.contains([1.0, 1.0, 1.0]) && !s.contains([2.0, 1.0, 0.0]));
/// assert!((s.bound([3.0, 0.0, 0.0]) - 1.0).abs() < 1e-12);
/// ```
#[derive(Debug, Clone, PartialEq)]
#[non_exhaustive]
pub enum Shape {
    /// A ball of radius `r`.
    Sphere {
        /// The radius.
        r: f64,
    },
    /// A box (the paper's prism) with half-extents `half` along x, y, z.
    Box {
        /// Half the side along each axis.
        half: [f64; 3],
    },
    /// An ellipsoid (the paper's spheroid) with semi-axes `r` along x, y, z.
    Ellipsoid {
        /// The semi-axes.
        r: [f64; 3],
    },
    /// An elliptic cylinder, axis z, semi-axes `r` in x and y, from `-half_h` to `half_h`.
    Cylinder {
        /// The semi-axes of the cross-section (x, y).
        r: [f64; 2],
        /// Half the height.
        half_h: f64,
    },
    /// A truncated cone, axis z: radius `r1` (along x) at `z = -half_h`, `r2` at
    /// `z = +half_h`; every cross-section is an ellipse whose y semi-axis is `aspect`
    /// times its x semi-axis.
    Cone {
        /// The radius (x semi-axis) of the base, at `z = -half_h`.
        r1: f64,
        /// The radius (x semi-axis) of the top, at `z = +half_h`.
        r2: f64,
        /// The y semi-axis over the x semi-axis (1 for a circular cone).
        aspect: f64,
        /// Half the height.
        half_h: f64,
    },
    /// A torus around the z axis: the tube of radius `minor` around the circle of
    /// radius `major` in the xy plane.
    Torus {
        /// The radius of the centre circle.
        major: f64,
        /// The radius of the tube.
        minor: f64,
    },
    /// A capsule: the points within `r` of the segment from `z = -half_h` to `half_h`.
    Capsule {
        /// The radius.
        r: f64,
        /// Half the length of the axis segment.
        half_h: f64,
    },
    /// The half-space `normal · p ≤ offset` (`normal` is a unit vector).
    HalfSpace {
        /// The outward unit normal.
        normal: [f64; 3],
        /// The signed distance of the plane from the origin along `normal`.
        offset: f64,
    },
    /// A convex polyhedron: the intersection of the half-spaces `n · p ≤ d` for each
    /// plane `[nx, ny, nz, d]`, with unit normals.
    Polyhedron {
        /// The planes, normals of unit length.
        planes: Vec<[f64; 4]>,
    },
}

#[inline]
fn dot(a: [f64; 3], b: [f64; 3]) -> f64 {
    a[0] * b[0] + a[1] * b[1] + a[2] * b[2]
}

#[inline]
fn len3(a: [f64; 3]) -> f64 {
    dot(a, a).sqrt()
}

impl Shape {
    /// A ball of radius `r`.
    #[must_use]
    pub fn sphere(r: f64) -> Self {
        Shape::Sphere { r }
    }

    /// A box of the given full side lengths.
    #[must_use]
    pub fn cuboid(size: [f64; 3]) -> Self {
        Shape::Box {
            half: [size[0] / 2.0, size[1] / 2.0, size[2] / 2.0],
        }
    }

    /// A half-space `normal · p ≤ offset`; `normal` need not be of unit length (the
    /// inequality is rescaled). Returns `None` for a zero or non-finite normal.
    #[must_use]
    pub fn half_space(normal: [f64; 3], offset: f64) -> Option<Self> {
        let l = len3(normal);
        if !(l.is_finite() && l > 0.0) {
            return None;
        }
        Some(Shape::HalfSpace {
            normal: [normal[0] / l, normal[1] / l, normal[2] / l],
            offset: offset / l,
        })
    }

    /// A convex polyhedron from planes `[nx, ny, nz, d]` meaning `n · p ≤ d`; normals
    /// need not be of unit length. Returns `None` when a normal is zero or non-finite.
    #[must_use]
    pub fn polyhedron(planes: &[[f64; 4]]) -> Option<Self> {
        let mut out = Vec::with_capacity(planes.len());
        for p in planes {
            let l = len3([p[0], p[1], p[2]]);
            if !(l.is_finite() && l > 0.0 && p[3].is_finite()) {
                return None;
            }
            out.push([p[0] / l, p[1] / l, p[2] / l, p[3] / l]);
        }
        Some(Shape::Polyhedron { planes: out })
    }

    /// Whether the local point `p` is inside (boundary included). This is the exact
    /// predicate the octree reproduces at voxel centres.
    ///
    /// # Runtime
    /// O(1), O(planes) for a polyhedron.
    #[must_use]
    #[inline]
    pub fn contains(&self, p: [f64; 3]) -> bool {
        let [x, y, z] = p;
        match self {
            Shape::Sphere { r } => dot(p, p) <= r * r,
            Shape::Box { half } => x.abs() <= half[0] && y.abs() <= half[1] && z.abs() <= half[2],
            Shape::Ellipsoid { r } => {
                let (a, b, c) = (x / r[0], y / r[1], z / r[2]);
                a * a + b * b + c * c <= 1.0
            }
            Shape::Cylinder { r, half_h } => {
                let (a, b) = (x / r[0], y / r[1]);
                z.abs() <= *half_h && a * a + b * b <= 1.0
            }
            Shape::Cone {
                r1,
                r2,
                aspect,
                half_h,
            } => {
                if z.abs() > *half_h {
                    return false;
                }
                let rz = r1 + (r2 - r1) * (z + half_h) / (2.0 * half_h);
                let yy = y / aspect;
                x * x + yy * yy <= rz * rz
            }
            Shape::Torus { major, minor } => {
                let q = (x * x + y * y).sqrt() - major;
                q * q + z * z <= minor * minor
            }
            Shape::Capsule { r, half_h } => {
                let dz = z.abs() - half_h;
                let dz = if dz > 0.0 { dz } else { 0.0 };
                x * x + y * y + dz * dz <= r * r
            }
            Shape::HalfSpace { normal, offset } => dot(*normal, p) <= *offset,
            Shape::Polyhedron { planes } => planes
                .iter()
                .all(|pl| pl[0] * x + pl[1] * y + pl[2] * z <= pl[3]),
        }
    }

    /// A 1-Lipschitz function of the local point `p`, negative inside and positive
    /// outside: a lower bound on the distance to the surface.
    ///
    /// # Runtime
    /// O(1), O(planes) for a polyhedron.
    #[must_use]
    #[inline]
    pub fn bound(&self, p: [f64; 3]) -> f64 {
        let [x, y, z] = p;
        match self {
            Shape::Sphere { r } => len3(p) - r,
            Shape::Box { half } => {
                let q = [x.abs() - half[0], y.abs() - half[1], z.abs() - half[2]];
                let outside = len3([q[0].max(0.0), q[1].max(0.0), q[2].max(0.0)]);
                outside + q[0].max(q[1]).max(q[2]).min(0.0)
            }
            Shape::Ellipsoid { r } => {
                let (a, b, c) = (x / r[0], y / r[1], z / r[2]);
                ((a * a + b * b + c * c).sqrt() - 1.0) * r[0].min(r[1]).min(r[2])
            }
            Shape::Cylinder { r, half_h } => {
                let (a, b) = (x / r[0], y / r[1]);
                let side = ((a * a + b * b).sqrt() - 1.0) * r[0].min(r[1]);
                side.max(z.abs() - half_h)
            }
            Shape::Cone {
                r1,
                r2,
                aspect,
                half_h,
            } => {
                let yy = y / aspect;
                let q = (x * x + yy * yy).sqrt();
                let h = 2.0 * half_h;
                let rz = r1 + (r2 - r1) * (z + half_h) / h;
                let side = (q - rz) * h / (h * h + (r1 - r2) * (r1 - r2)).sqrt();
                // The map (x, y) -> (x, y / aspect) stretches by up to 1 / aspect.
                side.max(z.abs() - half_h) / (1.0f64).max(1.0 / aspect)
            }
            Shape::Torus { major, minor } => {
                let q = (x * x + y * y).sqrt() - major;
                (q * q + z * z).sqrt() - minor
            }
            Shape::Capsule { r, half_h } => {
                let dz = (z.abs() - half_h).max(0.0);
                (x * x + y * y + dz * dz).sqrt() - r
            }
            Shape::HalfSpace { normal, offset } => dot(*normal, p) - offset,
            Shape::Polyhedron { planes } => planes
                .iter()
                .map(|pl| pl[0] * x + pl[1] * y + pl[2] * z - pl[3])
                .fold(f64::NEG_INFINITY, f64::max),
        }
    }

    /// The half-extents of an axis-aligned box around the origin holding the shape, or
    /// `None` for an unbounded shape (a half-space; a polyhedron with fewer than four
    /// vertices).
    #[must_use]
    pub fn local_half_extent(&self) -> Option<[f64; 3]> {
        Some(match self {
            Shape::Sphere { r } => [*r; 3],
            Shape::Box { half } => *half,
            Shape::Ellipsoid { r } => *r,
            Shape::Cylinder { r, half_h } => [r[0], r[1], *half_h],
            Shape::Cone {
                r1,
                r2,
                aspect,
                half_h,
            } => {
                let m = r1.max(*r2);
                [m, m * aspect, *half_h]
            }
            Shape::Torus { major, minor } => [major + minor, major + minor, *minor],
            Shape::Capsule { r, half_h } => [*r, *r, half_h + r],
            Shape::HalfSpace { .. } => return None,
            Shape::Polyhedron { planes } => {
                let vs = polyhedron_vertices(planes);
                if vs.len() < 4 {
                    return None;
                }
                let mut h = [0.0f64; 3];
                for v in vs {
                    for a in 0..3 {
                        h[a] = h[a].max(v[a].abs());
                    }
                }
                h
            }
        })
    }

    /// Checks the parameters: finite, radii and sizes positive, `r1, r2 ≥ 0` and not
    /// both zero. Returns a description of the first problem.
    ///
    /// # Errors
    /// A message naming the bad parameter.
    pub fn validate(&self) -> Result<(), String> {
        let pos = |name: &str, v: f64| {
            if v.is_finite() && v > 0.0 {
                Ok(())
            } else {
                Err(format!("`{name}` must be a positive number, got {v}"))
            }
        };
        match self {
            Shape::Sphere { r } => pos("r", *r),
            Shape::Box { half } => half.iter().try_for_each(|&h| pos("size", 2.0 * h)),
            Shape::Ellipsoid { r } => r.iter().try_for_each(|&v| pos("r", v)),
            Shape::Cylinder { r, half_h } => {
                r.iter().try_for_each(|&v| pos("r", v))?;
                pos("h", 2.0 * half_h)
            }
            Shape::Cone {
                r1,
                r2,
                aspect,
                half_h,
            } => {
                pos("h", 2.0 * half_h)?;
                pos("r1 aspect", *aspect)?;
                for (n, v) in [("r1", r1), ("r2", r2)] {
                    if !(v.is_finite() && *v >= 0.0) {
                        return Err(format!("`{n}` must be zero or positive, got {v}"));
                    }
                }
                if *r1 == 0.0 && *r2 == 0.0 {
                    return Err("`r1` and `r2` cannot both be zero".into());
                }
                Ok(())
            }
            Shape::Torus { major, minor } => {
                pos("major", *major)?;
                pos("minor", *minor)
            }
            Shape::Capsule { r, half_h } => {
                pos("r", *r)?;
                if half_h.is_finite() && *half_h >= 0.0 {
                    Ok(())
                } else {
                    Err(format!(
                        "`h` must be zero or positive, got {}",
                        2.0 * half_h
                    ))
                }
            }
            Shape::HalfSpace { normal, offset } => {
                if normal.iter().chain([offset]).all(|v| v.is_finite()) {
                    Ok(())
                } else {
                    Err("the half-space must have a finite normal and offset".into())
                }
            }
            Shape::Polyhedron { planes } => {
                if planes.is_empty() {
                    Err("a polyhedron needs at least one plane".into())
                } else {
                    Ok(())
                }
            }
        }
    }
}

/// The vertices of the polyhedron `n · p ≤ d` (every feasible intersection of three
/// planes). O(n⁴) for n planes: meant for the few planes a scene gives.
fn polyhedron_vertices(planes: &[[f64; 4]]) -> Vec<[f64; 3]> {
    let n = planes.len();
    let mut out = Vec::new();
    if n > 64 {
        return out;
    }
    for i in 0..n {
        for j in i + 1..n {
            for k in j + 1..n {
                let (a, b, c) = (planes[i], planes[j], planes[k]);
                let det = a[0] * (b[1] * c[2] - b[2] * c[1]) - a[1] * (b[0] * c[2] - b[2] * c[0])
                    + a[2] * (b[0] * c[1] - b[1] * c[0]);
                if det.abs() < 1e-12 {
                    continue;
                }
                // Cramer's rule.
                let solve = |col: usize| {
                    let m = |r: [f64; 4], q: usize| if q == col { r[3] } else { r[q] };
                    (m(a, 0) * (m(b, 1) * m(c, 2) - m(b, 2) * m(c, 1))
                        - m(a, 1) * (m(b, 0) * m(c, 2) - m(b, 2) * m(c, 0))
                        + m(a, 2) * (m(b, 0) * m(c, 1) - m(b, 1) * m(c, 0)))
                        / det
                };
                let v = [solve(0), solve(1), solve(2)];
                let scale = 1.0 + v.iter().fold(0.0f64, |m, x| m.max(x.abs()));
                if planes
                    .iter()
                    .all(|p| p[0] * v[0] + p[1] * v[1] + p[2] * v[2] <= p[3] + 1e-9 * scale)
                {
                    out.push(v);
                }
            }
        }
    }
    out
}
