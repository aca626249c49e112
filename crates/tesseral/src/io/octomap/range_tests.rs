//! OctoMap's key range (voxels −32768..32767 per axis) on write, against the native
//! format's full range, and maps with log-odds and free space through files.

use super::*;
use crate::io::{native, read_model, write_model};

fn one_voxel(v: crate::Voxel, free: Option<crate::Voxel>) -> Model {
    let all: Vec<crate::Voxel> = [Some(v), free].into_iter().flatten().collect();
    let space = LinearOctree::from_voxels_fitted(&all).unwrap();
    let (d, o) = (space.depth(), space.origin());
    let tree = LinearOctree::from_voxels(d, o, [v]).unwrap();
    let free = free.map(|f| LinearOctree::from_voxels(d, o, [f]).unwrap());
    Model::from_parts(tree, Frame::new(0.05, [0.0; 3]), None, free, None).unwrap()
}

#[test]
fn the_key_range_is_exactly_32768_each_way() {
    for axis in 0..3 {
        for (x, fits) in [
            (-32768, true),
            (32767, true),
            (-32769, false),
            (32768, false),
        ] {
            let mut v = [5, -7, 11];
            v[axis] = x;
            for free in [false, true] {
                // The out-of-range voxel occupied, or free beside an occupied one.
                let m = if free {
                    one_voxel([0, 0, 0], Some(v))
                } else {
                    one_voxel(v, None)
                };
                for r in [encode_bt(&m), encode_ot(&m)] {
                    match (fits, r) {
                        (true, Ok(bytes)) => {
                            let back = if bytes.starts_with(BT_HEADER.as_bytes()) {
                                decode_bt(&bytes)
                            } else {
                                decode_ot(&bytes)
                            }
                            .unwrap();
                            let known: Vec<_> = back.known().voxels().collect();
                            assert!(known.contains(&v), "{v:?} free={free}");
                        }
                        (false, Err(e)) => {
                            assert!(
                                e.contains("OctoMap keys reach only voxels −32768..32767"),
                                "{e}"
                            );
                        }
                        (fits, r) => panic!("{v:?} free={free}: fits {fits}, got {r:?}"),
                    }
                }
            }
        }
    }
}

#[test]
fn writing_out_of_range_names_the_file_and_the_native_format_keeps_it() {
    let dir = tempfile::tempdir().unwrap();
    let far = [1_000_000_000_000i64, -3, 4];
    let m = one_voxel(far, Some([far[0] - 5, 0, 0]));
    for ext in ["bt", "ot"] {
        let p = dir.path().join(format!("far.{ext}"));
        let e = write_model(&p, &m).unwrap_err();
        assert!(matches!(e.kind(), FormatError::Unsupported(_)), "{e:?}");
        let s = e.to_string();
        assert!(s.contains("far.") && s.contains("−32768..32767"), "{s}");
        assert!(!p.exists(), "nothing written");
    }
    let p = dir.path().join("far.tess");
    write_model(&p, &m).unwrap();
    let back = native::read(&p).unwrap();
    assert_eq!(back.tree.voxels().collect::<Vec<_>>(), vec![far]);
    assert_eq!(
        back.free.unwrap().voxels().collect::<Vec<_>>(),
        vec![[far[0] - 5, 0, 0]]
    );
}

#[test]
fn a_map_with_log_odds_and_free_space_goes_through_bt_and_ot_files() {
    let dir = tempfile::tempdir().unwrap();
    let occupied = [[0, 0, 0], [1, 0, 0], [-3, 2, 1]];
    let free: Vec<crate::Voxel> = (-4..0).flat_map(|x| [[x, 0, 0], [x, 1, 0]]).collect();
    let tree = LinearOctree::from_voxels(4, [-8; 3], occupied).unwrap();
    let free_t = LinearOctree::from_voxels(4, [-8; 3], free.iter().copied()).unwrap();
    let odds = occupied
        .iter()
        .map(|&v| (v, 0.85f32 + v[0].abs() as f32))
        .chain(free.iter().map(|&v| (v, -0.405f32 * (1 + v[1]) as f32)));
    let layer = Layer::from_voxels(4, [-8; 3], odds).unwrap();
    let m = Model::from_parts(
        tree,
        Frame::new(0.1, [0.0; 3]),
        None,
        Some(free_t),
        Some(layer),
    )
    .unwrap();
    let set = |t: &LinearOctree| {
        let mut v: Vec<_> = t.voxels().collect();
        v.sort_unstable();
        v
    };
    for ext in ["bt", "ot"] {
        let p = dir.path().join(format!("map.{ext}"));
        write_model(&p, &m).unwrap();
        let back = read_model(&p).unwrap();
        back.assert_valid();
        assert_eq!(back.frame.voxel_size, 0.1);
        assert_eq!(set(&back.tree), set(&m.tree), "{ext}: occupied");
        assert_eq!(
            set(back.free.as_ref().unwrap()),
            set(m.free.as_ref().unwrap()),
            "{ext}: free"
        );
        if ext == "ot" {
            let l = back.log_odds.as_ref().unwrap();
            for (v, x) in m
                .log_odds
                .as_ref()
                .unwrap()
                .to_voxels()
                .into_iter()
                .map(|(v, _, x)| (v, x))
            {
                assert_eq!(l.get(v).map(f32::to_bits), Some(x.to_bits()), "{v:?}");
            }
        }
    }
}
