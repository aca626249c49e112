//! The resident memory of a mapped `.tess` file (Linux: the mapping's `Rss` in
//! `/proc/self/smaps`) stays small while it is opened and read chunk by chunk with
//! releases: each page fault maps a window of pages around it (fault-around), so
//! releasing exactly the bytes read would leave a window per chunk behind.

use std::path::Path;

use super::{TessFile, TessWriter};
use crate::linear::Leaf;
use crate::model::Frame;

/// The resident kibibytes of the mappings of `path` in this process.
fn mapped_kib(path: &Path) -> u64 {
    let smaps = std::fs::read_to_string("/proc/self/smaps").unwrap();
    let name = path.to_str().unwrap();
    let mut on = false;
    let mut kib = 0;
    for line in smaps.lines() {
        let mut words = line.split_whitespace();
        let first = words.next().unwrap_or("");
        if first.contains('-') && first.chars().all(|c| c.is_ascii_hexdigit() || c == '-') {
            on = line.ends_with(name);
        } else if on && first == "Rss:" {
            kib += words.next().unwrap().parse::<u64>().unwrap();
        }
    }
    kib
}

/// A file of more than 12 MiB in 4,096 chunks (one voxel in eight of a depth-9
/// space: 16 Mi leaves that do not merge), in `dir`.
fn big_file(dir: &Path) -> std::path::PathBuf {
    let path = dir.join("big.tess");
    let mut w = TessWriter::new(
        std::io::BufWriter::new(std::fs::File::create(&path).unwrap()),
        9,
        [0, 0, 0],
    )
    .unwrap()
    .with_chunk_leaves(4096);
    for code in (0..1u64 << 27).step_by(8) {
        w.push(Leaf::new(code, 0)).unwrap();
    }
    w.finish(Frame::default()).unwrap();
    let size = std::fs::metadata(&path).unwrap().len();
    assert!(size > 12 << 20, "{size}");
    path
}

/// The most of a big file's mapping that may stay resident, in KiB.
const MOST: u64 = 4 << 10;

/// Opening the big file reads every chunk's head, and reading the chunks in order
/// with [`TessFile::release`] after each keeps a few hundred KiB mapped, not the
/// file.
#[test]
fn opening_and_reading_a_file_keep_its_mapped_pages_few() {
    let dir = tempfile::tempdir().unwrap();
    let path = big_file(dir.path());
    let f = TessFile::open(&path).unwrap();
    assert!(f.chunks().len() >= 4096);
    let open = mapped_kib(&path);
    assert!(open < MOST, "{open} KiB mapped after opening");
    let chunks = f.chunks();
    let mut peak = 0;
    for (i, c) in chunks.iter().enumerate() {
        assert_eq!(f.chunk(i).unwrap().len() as u64, c.count);
        let end = chunks.get(i + 1).map_or(u64::MAX, |n| n.offset);
        f.release(c.offset..end);
        if i % 256 == 0 {
            peak = peak.max(mapped_kib(&path));
        }
    }
    assert!(peak < MOST, "{peak} KiB mapped while reading");
}

/// `render --json` counts a streamed tree's voxels by reading every chunk: that
/// count lets the pages go too (it kept the whole file resident: 1.6 GiB more for
/// the depth-15 showcase).
#[test]
fn counting_a_streamed_trees_voxels_keeps_its_mapped_pages_few() {
    let dir = tempfile::tempdir().unwrap();
    let path = big_file(dir.path());
    let tree = crate::render::StreamedTree::open(&path, 1 << 20).unwrap();
    assert_eq!(tree.voxel_count().unwrap(), 1 << 24);
    let after = mapped_kib(&path);
    assert!(after < MOST, "{after} KiB mapped after counting the voxels");
}
