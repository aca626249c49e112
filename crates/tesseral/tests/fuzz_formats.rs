//! Stable-toolchain fuzzing of every parser: valid files, their mutations (bit flips,
//! truncations, splices, extreme values written over header fields) and random
//! bytes, from a seeded generator. Each input must give `Ok` or `Err`, never a panic,
//! and must not allocate far beyond its own size: a counting global allocator records
//! the peak live bytes while each parser runs. The cargo-fuzz targets in `fuzz/` run
//! the same parsers with coverage guidance.

use std::alloc::{GlobalAlloc, Layout, System};
use std::panic::{catch_unwind, AssertUnwindSafe};
use std::sync::atomic::{AtomicUsize, Ordering};
use std::sync::Mutex;

use rand::{Rng, SeedableRng};
use tesseral::io::mesh as meshio;
use tesseral::io::{binvox, native, octomap, vox, xyz, Frame, Model};
use tesseral::linear::LinearOctree;
use tesseral::mesh::{self, Resolution, VoxelizeOptions};
use tesseral::model::Layer;

struct Counting;
static LIVE: AtomicUsize = AtomicUsize::new(0);
static PEAK: AtomicUsize = AtomicUsize::new(0);

// SAFETY: forwards to the system allocator unchanged and only counts sizes.
unsafe impl GlobalAlloc for Counting {
    unsafe fn alloc(&self, layout: Layout) -> *mut u8 {
        let now = LIVE.fetch_add(layout.size(), Ordering::Relaxed) + layout.size();
        PEAK.fetch_max(now, Ordering::Relaxed);
        // SAFETY: same contract as the caller's.
        unsafe { System.alloc(layout) }
    }
    unsafe fn dealloc(&self, ptr: *mut u8, layout: Layout) {
        LIVE.fetch_sub(layout.size(), Ordering::Relaxed);
        // SAFETY: same contract as the caller's.
        unsafe { System.dealloc(ptr, layout) }
    }
    unsafe fn realloc(&self, ptr: *mut u8, layout: Layout, new_size: usize) -> *mut u8 {
        if new_size > layout.size() {
            let now = LIVE.fetch_add(new_size - layout.size(), Ordering::Relaxed) + new_size
                - layout.size();
            PEAK.fetch_max(now, Ordering::Relaxed);
        } else {
            LIVE.fetch_sub(layout.size() - new_size, Ordering::Relaxed);
        }
        // SAFETY: same contract as the caller's.
        unsafe { System.realloc(ptr, layout, new_size) }
    }
}

#[global_allocator]
static ALLOCATOR: Counting = Counting;

/// Tests share the counters: run them one at a time.
static SERIAL: Mutex<()> = Mutex::new(());

type Parser = fn(&[u8]) -> bool;

/// Runs `parse` on `input` and checks: no panic, peak extra allocation bounded.
fn run_one(name: &str, parse: Parser, input: &[u8], seed: u64, case: usize) {
    let base = LIVE.load(Ordering::Relaxed);
    PEAK.store(base, Ordering::Relaxed);
    let result = catch_unwind(AssertUnwindSafe(|| parse(input)));
    let peak = PEAK.load(Ordering::Relaxed).saturating_sub(base);
    assert!(
        result.is_ok(),
        "{name}: parser panicked (seed {seed}, case {case}, {} bytes: {:?})",
        input.len(),
        &input[..input.len().min(96)]
    );
    let limit = (32 << 20) + 8192 * input.len();
    assert!(
        peak <= limit,
        "{name}: allocated {peak} bytes for a {}-byte input (seed {seed}, case {case})",
        input.len()
    );
}

fn mutate(rng: &mut rand_pcg::Pcg64, seed: &[u8]) -> Vec<u8> {
    let mut b = seed.to_vec();
    let rounds = rng.random_range(1..6);
    for _ in 0..rounds {
        match rng.random_range(0..7) {
            0 if !b.is_empty() => {
                let i = rng.random_range(0..b.len());
                b[i] ^= 1 << rng.random_range(0..8);
            }
            1 if !b.is_empty() => {
                let n = rng.random_range(0..b.len());
                b.truncate(n);
            }
            2 => {
                let i = rng.random_range(0..=b.len());
                let n = rng.random_range(1..16);
                let junk: Vec<u8> = (0..n).map(|_| rng.random()).collect();
                b.splice(i..i, junk);
            }
            3 if b.len() >= 8 => {
                // Extreme values over a 4- or 8-byte field, as hostile headers do.
                let i = rng.random_range(0..b.len() - 7);
                let v: [u8; 8] = match rng.random_range(0..5) {
                    0 => u64::MAX.to_le_bytes(),
                    1 => (u32::MAX as u64).to_le_bytes(),
                    2 => (1u64 << 31).to_le_bytes(),
                    3 => (i32::MAX as u64).to_le_bytes(),
                    _ => 0u64.to_le_bytes(),
                };
                let w = if rng.random_bool(0.5) { 4 } else { 8 };
                b[i..i + w].copy_from_slice(&v[..w]);
            }
            4 if !b.is_empty() => {
                // Replace a decimal number in a text header by a huge one.
                let i = rng.random_range(0..b.len());
                let huge = [
                    "4294967295",
                    "99999999999999999999",
                    "-1",
                    "1e308",
                    "nan",
                    "0",
                ];
                let w = huge[rng.random_range(0..huge.len())].as_bytes();
                let end = (i + rng.random_range(1..4)).min(b.len());
                b.splice(i..end, w.iter().copied());
            }
            5 if b.len() > 1 => {
                let i = rng.random_range(0..b.len());
                let j = rng.random_range(0..b.len());
                b.swap(i, j);
            }
            _ => {
                let i = rng.random_range(0..=b.len());
                b.insert(i, rng.random());
            }
        }
    }
    b
}

fn fuzz(name: &str, parse: Parser, seeds: &[Vec<u8>], cases: usize) {
    let _guard = SERIAL.lock().unwrap_or_else(|e| e.into_inner());
    let seed = 0x7e55_e2a1 ^ name.len() as u64;
    let mut rng = rand_pcg::Pcg64::seed_from_u64(seed);
    for s in seeds {
        assert!(parse(s), "{name}: a valid seed input was refused");
    }
    for case in 0..cases {
        let input = if case % 10 == 0 {
            let n = rng.random_range(0..512);
            let mut b: Vec<u8> = (0..n).map(|_| rng.random()).collect();
            // Random bytes behind a valid beginning reach past the magic checks.
            if let Some(s) = seeds.get(case % seeds.len().max(1)) {
                let keep = rng.random_range(0..=s.len().min(64));
                b.splice(0..0, s[..keep].iter().copied());
            }
            b
        } else {
            mutate(&mut rng, &seeds[case % seeds.len()])
        };
        run_one(name, parse, &input, seed, case);
    }
}

fn sample_trees() -> Vec<LinearOctree> {
    let mut rng = rand_pcg::Pcg64::seed_from_u64(42);
    (0..4)
        .map(|i| {
            let voxels: Vec<_> = (0..20 + 30 * i)
                .map(|_| {
                    [
                        rng.random_range(-5..11),
                        rng.random_range(-5..11),
                        rng.random_range(0..16),
                    ]
                })
                .collect();
            LinearOctree::from_voxels(5, [-8, -8, -8], voxels).unwrap()
        })
        .chain([
            LinearOctree::full(2, [0; 3]).unwrap(),
            LinearOctree::empty(1, [0; 3]).unwrap(),
        ])
        .collect()
}

fn models() -> Vec<Model> {
    sample_trees()
        .into_iter()
        .map(|tree| {
            let pairs = tree.voxels().map(|v| (v, [v[0] as u8, 3, 4, 255]));
            let colors = Layer::from_voxels(tree.depth(), tree.origin(), pairs).unwrap();
            // Free space and log-odds too, so every section of every format is fuzzed.
            let free = tree.complement();
            let odds = Layer::from_voxels(
                tree.depth(),
                tree.origin(),
                tree.voxels().take(64).map(|v| (v, 0.85f32)),
            )
            .unwrap();
            Model::from_parts(
                tree,
                Frame::new(0.25, [1.0, 2.0, 3.0]),
                Some(colors),
                Some(free),
                Some(odds),
            )
            .unwrap()
        })
        .collect()
}

const CASES: usize = 1500;

#[test]
fn fuzz_native() {
    let seeds: Vec<Vec<u8>> = models().iter().map(native::encode).collect();
    fuzz("native", |b| native::decode(b).is_ok(), &seeds, CASES);
}

#[test]
fn fuzz_binvox() {
    let seeds: Vec<Vec<u8>> = models()
        .iter()
        .map(|m| binvox::encode(m).unwrap())
        .collect();
    fuzz("binvox", |b| binvox::decode(b).is_ok(), &seeds, CASES);
}

#[test]
fn fuzz_vox() {
    let seeds: Vec<Vec<u8>> = models()
        .iter()
        .filter(|m| !m.tree.is_empty())
        .map(|m| vox::encode(m).unwrap())
        .collect();
    fuzz("vox", |b| vox::decode(b).is_ok(), &seeds, CASES);
}

#[test]
fn fuzz_octomap_bt() {
    let seeds: Vec<Vec<u8>> = models()
        .iter()
        .map(|m| octomap::encode_bt(m).unwrap())
        .collect();
    fuzz("bt", |b| octomap::decode_bt(b).is_ok(), &seeds, CASES);
}

#[test]
fn fuzz_octomap_ot() {
    let mut seeds: Vec<Vec<u8>> = models()
        .iter()
        .map(|m| octomap::encode_ot(m).unwrap())
        .collect();
    seeds.extend(
        sample_trees()
            .into_iter()
            .map(|t| octomap::encode_ot(&Model::new(t)).unwrap()),
    );
    fuzz("ot", |b| octomap::decode_ot(b).is_ok(), &seeds, CASES);
}

#[test]
fn fuzz_xyz() {
    let seeds: Vec<Vec<u8>> = sample_trees()
        .iter()
        .map(|t| {
            let mut out = Vec::new();
            xyz::write(&mut out, t).unwrap();
            out
        })
        .collect();
    fuzz("xyz", |b| xyz::parse(b).is_ok(), &seeds, CASES);
}

/// Parses a mesh and, when it is small, voxelizes it both ways at a small depth:
/// neither may panic on any input.
fn parse_mesh(b: &[u8], ext: &str) -> bool {
    let Ok(m) = meshio::parse(b, ext) else {
        return false;
    };
    if m.triangles.len() <= 200 {
        for surface_only in [false, true] {
            let opts = VoxelizeOptions {
                resolution: Resolution::Depth(4),
                surface_only,
                ..Default::default()
            };
            let _ = mesh::voxelize(&m, &opts);
        }
    }
    true
}

fn mesh_seeds(ext: &str) -> Vec<Vec<u8>> {
    sample_trees()
        .iter()
        .filter(|t| !t.is_empty())
        .map(|t| {
            let m = mesh::boundary_mesh(t);
            let mut out = Vec::new();
            match ext {
                "stl" => meshio::write_stl(&mut out, &m),
                "obj" => meshio::write_obj(&mut out, &m),
                _ => meshio::write_ply(&mut out, &m),
            }
            .unwrap();
            out
        })
        .collect()
}

#[test]
fn fuzz_stl() {
    let mut seeds = mesh_seeds("stl");
    seeds.push(
        b"solid t\nfacet normal 0 0 1\nouter loop\nvertex 0 0 0\nvertex 1 0 0\nvertex 0 1 0\nendloop\nendfacet\nendsolid t\n".to_vec(),
    );
    fuzz("stl", |b| parse_mesh(b, "stl"), &seeds, CASES / 2);
}

#[test]
fn fuzz_obj() {
    fuzz(
        "obj",
        |b| parse_mesh(b, "obj"),
        &mesh_seeds("obj"),
        CASES / 2,
    );
}

#[test]
fn fuzz_ply() {
    let mut seeds = mesh_seeds("ply");
    seeds.push(
        b"ply\nformat ascii 1.0\nelement vertex 3\nproperty float x\nproperty float y\nproperty float z\nelement face 1\nproperty list uchar int vertex_indices\nend_header\n0 0 0\n1 0 0\n0 1 0\n3 0 1 2\n".to_vec(),
    );
    fuzz("ply", |b| parse_mesh(b, "ply"), &seeds, CASES / 2);
}

/// The committed seeds of a scan fuzz target.
fn scan_seeds(target: &str) -> Vec<Vec<u8>> {
    let dir = std::path::Path::new(env!("CARGO_MANIFEST_DIR"))
        .join("../../fuzz/corpus")
        .join(target);
    let mut files: Vec<_> = std::fs::read_dir(&dir)
        .unwrap_or_else(|e| panic!("{}: {e}", dir.display()))
        .map(|e| e.unwrap().path())
        .collect();
    files.sort();
    files.iter().map(|f| std::fs::read(f).unwrap()).collect()
}

#[test]
fn fuzz_scans() {
    use tesseral::io::scan::{parse, ScanFormat};
    let formats: [(&str, Parser); 5] = [
        ("scan_graph", |b| parse(b, ScanFormat::Graph).is_ok()),
        ("scan_log", |b| parse(b, ScanFormat::Log).is_ok()),
        ("scan_xyz", |b| parse(b, ScanFormat::Xyz).is_ok()),
        ("scan_ply", |b| parse(b, ScanFormat::Ply).is_ok()),
        ("scan_pcd", |b| parse(b, ScanFormat::Pcd).is_ok()),
    ];
    for (name, parser) in formats {
        fuzz(name, parser, &scan_seeds(name), CASES / 2);
    }
}

#[test]
fn hostile_scan_headers_are_refused_cheaply() {
    use tesseral::io::scan::{parse, ScanFormat};
    let _guard = SERIAL.lock().unwrap_or_else(|e| e.into_inner());
    let mut graph = u32::MAX.to_le_bytes().to_vec();
    graph.extend_from_slice(&[0; 80]);
    let mut points = 1u32.to_le_bytes().to_vec();
    points.extend_from_slice(&u32::MAX.to_le_bytes());
    points.extend_from_slice(&[0; 80]);
    let pcd = |data: &str| {
        format!("VERSION 0.7\nFIELDS x y z\nSIZE 4 4 4\nTYPE F F F\nCOUNT 1 1 1\nPOINTS 4000000000\nDATA {data}\n1 2 3\n").into_bytes()
    };
    let cases: Vec<(&str, Parser, Vec<u8>)> = vec![
        (
            "graph nodes",
            |b| parse(b, ScanFormat::Graph).is_ok(),
            graph,
        ),
        (
            "graph points",
            |b| parse(b, ScanFormat::Graph).is_ok(),
            points,
        ),
        (
            "pcd ascii",
            |b| parse(b, ScanFormat::Pcd).is_ok(),
            pcd("ascii"),
        ),
        (
            "pcd binary",
            |b| parse(b, ScanFormat::Pcd).is_ok(),
            pcd("binary"),
        ),
    ];
    for (name, parse, input) in cases {
        run_one(name, parse, &input, 0, 0);
        assert!(!parse(&input), "{name}: hostile input accepted");
    }
}

#[test]
fn compressed_pcd_holds_only_its_points() {
    // 3,000 points of x y z and 4,096 doubles: 98 MB uncompressed in a 1.1 MB
    // file. The reader streams the LZF output through a window and keeps the
    // points (72 KB), not the uncompressed data (or two copies of it).
    use tesseral::io::scan::{parse, ScanFormat};
    let _guard = SERIAL.lock().unwrap_or_else(|e| e.into_inner());
    let (n, record) = (3000usize, 12 + 8 * 4096);
    let size = n * record;
    let mut packed = vec![0u8, 0];
    let refs = (size - 1) / 264;
    for _ in 0..refs {
        packed.extend_from_slice(&[0xe0, 255, 0]);
    }
    let last = size - 1 - refs * 264;
    assert!((9..264).contains(&last));
    packed.extend_from_slice(&[0xe0, (last - 9) as u8, 0]);
    let mut input = format!("VERSION 0.7\nFIELDS x y z pad\nSIZE 4 4 4 8\nTYPE F F F F\nCOUNT 1 1 1 4096\nPOINTS {n}\nDATA binary_compressed\n").into_bytes();
    input.extend_from_slice(&(packed.len() as u32).to_le_bytes());
    input.extend_from_slice(&(size as u32).to_le_bytes());
    input.extend_from_slice(&packed);
    let base = LIVE.load(Ordering::Relaxed);
    PEAK.store(base, Ordering::Relaxed);
    let scans = parse(&input, ScanFormat::Pcd).unwrap();
    let peak = PEAK.load(Ordering::Relaxed).saturating_sub(base);
    assert_eq!(scans[0].points.len(), n);
    assert!(
        peak < 24 * n + (2 << 20),
        "{peak} bytes at most for {n} points of {size} uncompressed bytes"
    );
}

#[test]
fn hostile_headers_are_refused_cheaply() {
    let _guard = SERIAL.lock().unwrap_or_else(|e| e.into_inner());
    let cases: Vec<(&str, Parser, Vec<u8>)> = vec![
        ("binvox dim", |b| binvox::decode(b).is_ok(), b"#binvox 1\ndim 2097152 2097152 2097152\ndata\n\x01\xff".to_vec()),
        ("bt size", |b| octomap::decode_bt(b).is_ok(), b"# Octomap OcTree binary file\nid OcTree\nsize 4294967295\nres 0.1\ndata\n\xff\xff".to_vec()),
        ("ply count", |b| meshio::parse(b, "ply").is_ok(), b"ply\nformat binary_little_endian 1.0\nelement vertex 4294967295\nproperty double x\nproperty double y\nproperty double z\nend_header\n".to_vec()),
        ("stl count", |b| meshio::parse(b, "stl").is_ok(), {
            let mut v = vec![0u8; 84];
            v[80..84].copy_from_slice(&u32::MAX.to_le_bytes());
            v
        }),
        ("vox count", |b| vox::decode(b).is_ok(), {
            let mut v = b"VOX \x96\0\0\0MAIN\0\0\0\0\x24\0\0\0SIZE\x0c\0\0\0\0\0\0\0\x02\0\0\0\x02\0\0\0\x02\0\0\0XYZI\x04\0\0\0\0\0\0\0".to_vec();
            v.extend_from_slice(&u32::MAX.to_le_bytes());
            v
        }),
    ];
    for (name, parse, input) in cases {
        run_one(name, parse, &input, 0, 0);
        assert!(!parse(&input), "{name}: hostile input accepted");
    }
}

#[test]
fn the_guards_catch_a_greedy_or_panicking_parser() {
    let _guard = SERIAL.lock().unwrap_or_else(|e| e.into_inner());
    let greedy: Parser = |b| std::hint::black_box(vec![0u8; 200 << 20]).len() > b.len();
    let caught = catch_unwind(|| run_one("greedy", greedy, b"tiny", 0, 0));
    assert!(
        caught.is_err(),
        "a 200 MB allocation for 4 bytes went unnoticed"
    );
    let panicky: Parser = |b| b[usize::MAX / 2] == 0;
    let caught = catch_unwind(|| run_one("panicky", panicky, b"tiny", 0, 0));
    assert!(caught.is_err());
}
