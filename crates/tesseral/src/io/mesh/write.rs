//! Mesh writers: STL (binary), OBJ, PLY (binary little-endian) and glTF binary
//! (`.glb`). OBJ, PLY and glTF keep the shared (and split) vertices; STL stores each
//! triangle on its own, as the format requires.

use std::io::{self, Write};
use std::path::Path;

use crate::io::{extension, write_atomic, FormatError};
use crate::mesh::TriMesh;

/// The mesh extensions we write.
pub const MESH_EXTENSIONS: &str = "stl, obj, ply, glb";

/// Writes `mesh` to `path` atomically, choosing the format by extension.
///
/// # Errors
/// [`FormatError::UnknownFormat`] for another extension; [`FormatError::Io`].
pub fn write_file(path: &Path, mesh: &TriMesh) -> Result<(), FormatError> {
    let ext = extension(path);
    let f: fn(&mut dyn Write, &TriMesh) -> io::Result<()> = match ext.as_str() {
        "stl" => write_stl,
        "obj" => write_obj,
        "ply" => write_ply,
        "glb" => write_glb,
        _ => {
            return Err(FormatError::UnknownFormat {
                known: MESH_EXTENSIONS,
            }
            .with_path(path))
        }
    };
    write_atomic(path, |w| f(w, mesh))
}

fn normal(m: &TriMesh, t: &[u32; 3]) -> [f32; 3] {
    let [a, b, c] = t.map(|i| m.positions[i as usize]);
    let u = [b[0] - a[0], b[1] - a[1], b[2] - a[2]];
    let v = [c[0] - a[0], c[1] - a[1], c[2] - a[2]];
    let n = [
        u[1] * v[2] - u[2] * v[1],
        u[2] * v[0] - u[0] * v[2],
        u[0] * v[1] - u[1] * v[0],
    ];
    let l = (n[0] * n[0] + n[1] * n[1] + n[2] * n[2]).sqrt();
    if l > 0.0 {
        n.map(|x| (x / l) as f32)
    } else {
        [0.0; 3]
    }
}

/// Binary STL: 80-byte header, triangle count, then normal, three vertices and a
/// zero attribute per triangle.
///
/// # Errors
/// I/O errors of `w`.
pub fn write_stl(w: &mut dyn Write, m: &TriMesh) -> io::Result<()> {
    let mut header = [b' '; 80];
    let text = b"binary STL written by tesseral";
    header[..text.len()].copy_from_slice(text);
    w.write_all(&header)?;
    w.write_all(&(m.triangles.len() as u32).to_le_bytes())?;
    for t in &m.triangles {
        for x in normal(m, t) {
            w.write_all(&x.to_le_bytes())?;
        }
        for &i in t {
            for x in m.positions[i as usize] {
                w.write_all(&(x as f32).to_le_bytes())?;
            }
        }
        w.write_all(&[0, 0])?;
    }
    Ok(())
}

/// Wavefront OBJ: `v x y z` lines, then `f a b c` with 1-based indices.
///
/// # Errors
/// I/O errors of `w`.
pub fn write_obj(w: &mut dyn Write, m: &TriMesh) -> io::Result<()> {
    writeln!(
        w,
        "# written by tesseral: {} vertices, {} triangles",
        m.positions.len(),
        m.triangles.len()
    )?;
    for p in &m.positions {
        writeln!(w, "v {} {} {}", p[0], p[1], p[2])?;
    }
    for t in &m.triangles {
        writeln!(w, "f {} {} {}", t[0] + 1, t[1] + 1, t[2] + 1)?;
    }
    Ok(())
}

/// Binary little-endian PLY with float vertices and `uchar`/`int` face lists, and
/// `uchar` red, green, blue per face when the mesh has colours.
///
/// # Errors
/// I/O errors of `w`.
pub fn write_ply(w: &mut dyn Write, m: &TriMesh) -> io::Result<()> {
    let coloured = m.colors.len() == m.triangles.len() && !m.colors.is_empty();
    let face_colour = if coloured {
        "property uchar red\nproperty uchar green\nproperty uchar blue\n"
    } else {
        ""
    };
    write!(
        w,
        "ply\nformat binary_little_endian 1.0\ncomment written by tesseral\nelement vertex {}\nproperty float x\nproperty float y\nproperty float z\nelement face {}\nproperty list uchar int vertex_indices\n{face_colour}end_header\n",
        m.positions.len(),
        m.triangles.len()
    )?;
    let mut buf = Vec::with_capacity(12 * m.positions.len() + 13 * m.triangles.len());
    for p in &m.positions {
        for x in p {
            buf.extend_from_slice(&(*x as f32).to_le_bytes());
        }
    }
    for (k, t) in m.triangles.iter().enumerate() {
        buf.push(3);
        for &i in t {
            buf.extend_from_slice(&(i as i32).to_le_bytes());
        }
        if coloured {
            buf.extend_from_slice(&m.colors[k]);
        }
    }
    w.write_all(&buf)
}

/// glTF 2.0 binary: one mesh, one triangle primitive with `POSITION` (float VEC3,
/// with its bounds) and `u32` indices. A coloured mesh is written with its
/// vertices repeated per triangle and a `COLOR_0` attribute, so each face keeps its
/// own colour.
///
/// # Errors
/// I/O errors of `w`.
pub fn write_glb(w: &mut dyn Write, m: &TriMesh) -> io::Result<()> {
    if !m.colors.is_empty() && m.colors.len() == m.triangles.len() {
        return write_glb_coloured(w, m);
    }
    if m.triangles.is_empty() {
        // glTF accessors and buffers may not be empty: an empty scene instead.
        let json = br#"{"asset":{"version":"2.0","generator":"tesseral"},"scene":0,"scenes":[{"nodes":[]}]}"#;
        let mut json = json.to_vec();
        while json.len() % 4 != 0 {
            json.push(b' ');
        }
        w.write_all(b"glTF")?;
        w.write_all(&2u32.to_le_bytes())?;
        w.write_all(&((12 + 8 + json.len()) as u32).to_le_bytes())?;
        w.write_all(&(json.len() as u32).to_le_bytes())?;
        w.write_all(b"JSON")?;
        return w.write_all(&json);
    }
    let mut bin = Vec::with_capacity(12 * m.positions.len() + 12 * m.triangles.len());
    let mut lo = [f32::INFINITY; 3];
    let mut hi = [f32::NEG_INFINITY; 3];
    debug_assert!(!m.positions.is_empty());
    for p in &m.positions {
        for a in 0..3 {
            let x = p[a] as f32;
            lo[a] = lo[a].min(x);
            hi[a] = hi[a].max(x);
            bin.extend_from_slice(&x.to_le_bytes());
        }
    }
    let pos_len = bin.len();
    for t in &m.triangles {
        for &i in t {
            bin.extend_from_slice(&i.to_le_bytes());
        }
    }
    let idx_len = bin.len() - pos_len;
    while bin.len() % 4 != 0 {
        bin.push(0);
    }
    let json = serde_json::json!({
        "asset": {"version": "2.0", "generator": "tesseral"},
        "scene": 0,
        "scenes": [{"nodes": [0]}],
        "nodes": [{"mesh": 0}],
        "meshes": [{"primitives": [{"attributes": {"POSITION": 0}, "indices": 1, "mode": 4}]}],
        "buffers": [{"byteLength": bin.len()}],
        "bufferViews": [
            {"buffer": 0, "byteOffset": 0, "byteLength": pos_len, "target": 34962},
            {"buffer": 0, "byteOffset": pos_len, "byteLength": idx_len, "target": 34963}
        ],
        "accessors": [
            {"bufferView": 0, "componentType": 5126, "count": m.positions.len(), "type": "VEC3",
             "min": lo, "max": hi},
            {"bufferView": 1, "componentType": 5125, "count": 3 * m.triangles.len(), "type": "SCALAR"}
        ]
    });
    let mut json = serde_json::to_vec(&json).map_err(io::Error::other)?;
    while json.len() % 4 != 0 {
        json.push(b' ');
    }
    let total = 12 + 8 + json.len() + 8 + bin.len();
    w.write_all(b"glTF")?;
    w.write_all(&2u32.to_le_bytes())?;
    w.write_all(&(total as u32).to_le_bytes())?;
    w.write_all(&(json.len() as u32).to_le_bytes())?;
    w.write_all(b"JSON")?;
    w.write_all(&json)?;
    w.write_all(&(bin.len() as u32).to_le_bytes())?;
    w.write_all(b"BIN\0")?;
    w.write_all(&bin)
}

/// A coloured glTF: three vertices per triangle, `COLOR_0` as normalized RGBA bytes.
fn write_glb_coloured(w: &mut dyn Write, m: &TriMesh) -> io::Result<()> {
    let n = 3 * m.triangles.len();
    let mut bin = Vec::with_capacity(16 * n);
    let mut lo = [f32::INFINITY; 3];
    let mut hi = [f32::NEG_INFINITY; 3];
    for t in &m.triangles {
        for &i in t {
            let p = m.positions[i as usize];
            for a in 0..3 {
                let x = p[a] as f32;
                lo[a] = lo[a].min(x);
                hi[a] = hi[a].max(x);
                bin.extend_from_slice(&x.to_le_bytes());
            }
        }
    }
    let pos_len = bin.len();
    for c in &m.colors {
        for _ in 0..3 {
            bin.extend_from_slice(&[c[0], c[1], c[2], 255]);
        }
    }
    let col_len = bin.len() - pos_len;
    let json = serde_json::json!({
        "asset": {"version": "2.0", "generator": "tesseral"},
        "scene": 0,
        "scenes": [{"nodes": [0]}],
        "nodes": [{"mesh": 0}],
        "meshes": [{"primitives": [{"attributes": {"POSITION": 0, "COLOR_0": 1}, "mode": 4}]}],
        "buffers": [{"byteLength": bin.len()}],
        "bufferViews": [
            {"buffer": 0, "byteOffset": 0, "byteLength": pos_len, "target": 34962},
            {"buffer": 0, "byteOffset": pos_len, "byteLength": col_len, "target": 34962}
        ],
        "accessors": [
            {"bufferView": 0, "componentType": 5126, "count": n, "type": "VEC3",
             "min": lo, "max": hi},
            {"bufferView": 1, "componentType": 5121, "normalized": true, "count": n, "type": "VEC4"}
        ]
    });
    let mut json = serde_json::to_vec(&json).map_err(io::Error::other)?;
    while json.len() % 4 != 0 {
        json.push(b' ');
    }
    let total = 12 + 8 + json.len() + 8 + bin.len();
    w.write_all(b"glTF")?;
    w.write_all(&2u32.to_le_bytes())?;
    w.write_all(&(total as u32).to_le_bytes())?;
    w.write_all(&(json.len() as u32).to_le_bytes())?;
    w.write_all(b"JSON")?;
    w.write_all(&json)?;
    w.write_all(&(bin.len() as u32).to_le_bytes())?;
    w.write_all(b"BIN\0")?;
    w.write_all(&bin)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn glb_is_well_formed() {
        let tree =
            crate::linear::LinearOctree::from_voxels(2, [0; 3], [[0, 0, 0], [1, 1, 1]]).unwrap();
        let m = crate::mesh::boundary_mesh(&tree);
        let mut b = Vec::new();
        write_glb(&mut b, &m).unwrap();
        let u = |i: usize| u32::from_le_bytes([b[i], b[i + 1], b[i + 2], b[i + 3]]) as usize;
        assert_eq!(&b[..4], b"glTF");
        assert_eq!((u(4), u(8)), (2, b.len()));
        let json_len = u(12);
        assert_eq!(&b[16..20], b"JSON");
        assert_eq!(json_len % 4, 0);
        let json: serde_json::Value = serde_json::from_slice(&b[20..20 + json_len]).unwrap();
        let bin_at = 20 + json_len;
        assert_eq!(&b[bin_at + 4..bin_at + 8], b"BIN\0");
        let bin_len = u(bin_at);
        assert_eq!(bin_at + 8 + bin_len, b.len());
        assert_eq!(json["buffers"][0]["byteLength"], bin_len);
        assert_eq!(json["accessors"][0]["count"], m.positions.len());
        assert_eq!(json["accessors"][1]["count"], 3 * m.triangles.len());
        let views = &json["bufferViews"];
        let end =
            views[1]["byteOffset"].as_u64().unwrap() + views[1]["byteLength"].as_u64().unwrap();
        assert!(end as usize <= bin_len);
        assert_eq!(views[0]["byteLength"], 12 * m.positions.len());
        // An empty solid gives an empty scene, still a valid file.
        let mut e = Vec::new();
        write_glb(&mut e, &TriMesh::default()).unwrap();
        let n = u32::from_le_bytes([e[12], e[13], e[14], e[15]]) as usize;
        let json: serde_json::Value = serde_json::from_slice(&e[20..20 + n]).unwrap();
        assert_eq!(json["scenes"][0]["nodes"], serde_json::json!([]));
        assert_eq!(e.len(), 20 + n);
    }
}
