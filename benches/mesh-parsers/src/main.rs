//! Parse speed of our STL/OBJ/PLY readers against the crates made for the job
//! (stl_io, tobj, ply-rs-bw) on one 1 M-triangle sphere, best of 5. Run with
//! `cargo run --release --manifest-path benches/mesh-parsers/Cargo.toml`.

use std::io::Cursor;
use std::time::Instant;
fn best<F: FnMut() -> usize>(mut f: F) -> (f64, usize) {
    let mut b = f64::MAX;
    let mut n = 0;
    for _ in 0..5 {
        let t = Instant::now();
        n = f();
        b = b.min(t.elapsed().as_secs_f64());
    }
    (b, n)
}
fn main() {
    // A UV sphere with about 1 M triangles.
    let (nu, nv) = (1000usize, 500usize);
    let mut verts = vec![];
    for j in 0..=nv {
        for i in 0..nu {
            let (t, p) = (
                std::f64::consts::PI * j as f64 / nv as f64,
                2.0 * std::f64::consts::PI * i as f64 / nu as f64,
            );
            verts.push([
                (t.sin() * p.cos() * 50.0) as f32,
                (t.sin() * p.sin() * 50.0) as f32,
                (t.cos() * 50.0) as f32,
            ]);
        }
    }
    let mut tris = vec![];
    for j in 0..nv {
        for i in 0..nu {
            let a = j * nu + i;
            let b = j * nu + (i + 1) % nu;
            let c = a + nu;
            let d = b + nu;
            tris.push([a, c, b]);
            tris.push([b, c, d]);
        }
    }
    // binary STL
    let mut stl = vec![0u8; 80];
    stl.extend((tris.len() as u32).to_le_bytes());
    for t in &tris {
        stl.extend([0u8; 12]);
        for &k in t {
            for c in verts[k] {
                stl.extend(c.to_le_bytes());
            }
        }
        stl.extend([0u8; 2]);
    }
    // OBJ
    let mut obj = String::new();
    for v in &verts {
        obj += &format!("v {} {} {}\n", v[0], v[1], v[2]);
    }
    for t in &tris {
        obj += &format!("f {} {} {}\n", t[0] + 1, t[1] + 1, t[2] + 1);
    }
    // binary PLY
    let mut ply = format!("ply\nformat binary_little_endian 1.0\nelement vertex {}\nproperty float x\nproperty float y\nproperty float z\nelement face {}\nproperty list uchar int vertex_indices\nend_header\n", verts.len(), tris.len()).into_bytes();
    for v in &verts {
        for c in v {
            ply.extend(c.to_le_bytes());
        }
    }
    for t in &tris {
        ply.push(3);
        for &k in t {
            ply.extend((k as i32).to_le_bytes());
        }
    }
    println!(
        "{} triangles; STL {} MB, OBJ {} MB, PLY {} MB",
        tris.len(),
        stl.len() >> 20,
        obj.len() >> 20,
        ply.len() >> 20
    );
    let ours = best(|| tesseral::io::mesh::parse_stl(&stl).unwrap().triangles.len());
    let theirs = best(|| {
        stl_io::read_stl(&mut Cursor::new(&stl))
            .unwrap()
            .faces
            .len()
    });
    println!(
        "STL binary: tesseral {:.1} ms ({} tris), stl_io {:.1} ms ({} faces): {:.2}x",
        ours.0 * 1e3,
        ours.1,
        theirs.0 * 1e3,
        theirs.1,
        theirs.0 / ours.0
    );
    let ours = best(|| {
        tesseral::io::mesh::parse_obj(obj.as_bytes())
            .unwrap()
            .triangles
            .len()
    });
    let theirs = best(|| {
        let (m, _) = tobj::load_obj_buf(
            &mut Cursor::new(obj.as_bytes()),
            &tobj::GPU_LOAD_OPTIONS,
            |_| Ok(Default::default()),
        )
        .unwrap();
        m[0].mesh.indices.len() / 3
    });
    println!(
        "OBJ: tesseral {:.1} ms ({} tris), tobj {:.1} ms ({} tris): {:.2}x",
        ours.0 * 1e3,
        ours.1,
        theirs.0 * 1e3,
        theirs.1,
        theirs.0 / ours.0
    );
    let ours = best(|| tesseral::io::mesh::parse_ply(&ply).unwrap().triangles.len());
    let theirs = best(|| {
        let p = ply_rs_bw::parser::Parser::<ply_rs_bw::ply::DefaultElement>::new();
        let m = p.read_ply(&mut Cursor::new(&ply)).unwrap();
        m.payload["face"].len()
    });
    println!(
        "PLY binary: tesseral {:.1} ms ({} tris), ply-rs-bw {:.1} ms ({} faces): {:.2}x",
        ours.0 * 1e3,
        ours.1,
        theirs.0 * 1e3,
        theirs.1,
        theirs.0 / ours.0
    );
}
