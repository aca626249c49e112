//! The surface as a polygon mesh: Wavefront OBJ or ASCII PLY, one quad per plaquette,
//! lattice points shared, faces wound counter-clockwise seen from outside.
//!
//! ```
//! use tesseral::rsmc::{mesh, Direction, Face};
//! let faces = Direction::ALL.map(|dir| Face { voxel: [0, 0, 0], dir });
//! let mut obj = Vec::new();
//! mesh::write_obj(&faces, &mut obj).unwrap();
//! let text = String::from_utf8(obj).unwrap();
//! assert_eq!(text.lines().filter(|l| l.starts_with("v ")).count(), 8);
//! assert_eq!(text.lines().filter(|l| l.starts_with("f ")).count(), 6);
//! ```

use std::collections::HashMap;
use std::io::{self, Write};

use super::Face;
use crate::Voxel;

/// The four corners of a plaquette, counter-clockwise seen from outside.
#[must_use]
pub fn corners(f: Face) -> [Voxel; 4] {
    let axis = f.dir.axis() as usize;
    let positive = f.dir.is_positive();
    let (a, b) = ((axis + 1) % 3, (axis + 2) % 3);
    let mut base = f.voxel;
    if positive {
        base[axis] += 1;
    }
    let mut c = [base; 4];
    // base, +a, +a+b, +b winds counter-clockwise about +axis (e_a × e_b = e_axis).
    c[1][a] += 1;
    c[2][a] += 1;
    c[2][b] += 1;
    c[3][b] += 1;
    if !positive {
        c.swap(1, 3);
    }
    c
}

/// Shared vertices and quads (indices into the vertices) of the faces. O(F).
#[must_use]
pub fn indexed(faces: &[Face]) -> (Vec<Voxel>, Vec<[u32; 4]>) {
    let mut index: HashMap<Voxel, u32> = HashMap::with_capacity(faces.len());
    let mut vertices = Vec::new();
    let mut quads = Vec::with_capacity(faces.len());
    for &f in faces {
        let mut q = [0u32; 4];
        for (k, c) in corners(f).into_iter().enumerate() {
            q[k] = *index.entry(c).or_insert_with(|| {
                vertices.push(c);
                (vertices.len() - 1) as u32
            });
        }
        quads.push(q);
    }
    (vertices, quads)
}

/// Writes the faces as Wavefront OBJ. O(F).
///
/// # Errors
/// Errors of the writer.
pub fn write_obj<W: Write>(faces: &[Face], mut w: W) -> io::Result<()> {
    let (vertices, quads) = indexed(faces);
    writeln!(w, "# tesseral rsmc surface: {} plaquettes", faces.len())?;
    for v in &vertices {
        writeln!(w, "v {} {} {}", v[0], v[1], v[2])?;
    }
    for q in &quads {
        writeln!(w, "f {} {} {} {}", q[0] + 1, q[1] + 1, q[2] + 1, q[3] + 1)?;
    }
    w.flush()
}

/// Writes the faces as ASCII PLY. O(F).
///
/// # Errors
/// Errors of the writer.
pub fn write_ply<W: Write>(faces: &[Face], mut w: W) -> io::Result<()> {
    let (vertices, quads) = indexed(faces);
    writeln!(w, "ply\nformat ascii 1.0\ncomment tesseral rsmc surface")?;
    writeln!(
        w,
        "element vertex {}\nproperty int x\nproperty int y\nproperty int z",
        vertices.len()
    )?;
    writeln!(
        w,
        "element face {}\nproperty list uchar int vertex_indices\nend_header",
        quads.len()
    )?;
    for v in &vertices {
        writeln!(w, "{} {} {}", v[0], v[1], v[2])?;
    }
    for q in &quads {
        writeln!(w, "4 {} {} {} {}", q[0], q[1], q[2], q[3])?;
    }
    w.flush()
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::lattice::Direction;

    #[test]
    fn cube_is_closed_and_outward() {
        let faces: Vec<Face> = Direction::ALL
            .map(|dir| Face {
                voxel: [2, 3, 4],
                dir,
            })
            .to_vec();
        let (v, q) = indexed(&faces);
        assert_eq!(v.len(), 8);
        // Outward: the signed volume by the divergence theorem is +1.
        let mut vol6 = 0i64;
        for quad in &q {
            let p: Vec<Voxel> = quad.iter().map(|&i| v[i as usize]).collect();
            for t in [[0, 1, 2], [0, 2, 3]] {
                let (a, b, c) = (p[t[0]], p[t[1]], p[t[2]]);
                vol6 += a[0] * (b[1] * c[2] - b[2] * c[1]) - a[1] * (b[0] * c[2] - b[2] * c[0])
                    + a[2] * (b[0] * c[1] - b[1] * c[0]);
            }
        }
        assert_eq!(vol6, 6);
        // Every directed edge appears once, and its reverse once: closed and oriented.
        let mut edges = std::collections::HashMap::new();
        for quad in &q {
            for k in 0..4 {
                *edges.entry((quad[k], quad[(k + 1) % 4])).or_insert(0) += 1;
            }
        }
        for (&(a, b), &n) in &edges {
            assert_eq!(n, 1);
            assert_eq!(edges.get(&(b, a)), Some(&1));
        }
    }
}
