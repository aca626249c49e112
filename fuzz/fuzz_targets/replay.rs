#![no_main]
//! Fuzzes `tesseral replay`: the operations log parser the binary uses (included
//! from the CLI's source), and the dynamic octree under the operations it yields,
//! checked against a `HashSet` of voxels after every operation and validated at the
//! end. Coordinates are spread over all of `i64`.
use libfuzzer_sys::fuzz_target;
use std::collections::HashSet;
use tesseral::dynamic::DynamicOctree;

#[path = "../../crates/tesseral-cli/src/cmd/replay_log.rs"]
#[allow(dead_code)]
mod replay_log;
use replay_log::{parse_line, read_line, Op};

fuzz_target!(|data: &[u8]| {
    let mut tree = DynamicOctree::new();
    let mut model = HashSet::new();
    let mut reader = data;
    let mut buf = Vec::new();
    let mut ops = 0;
    while let Ok(true) = read_line(&mut reader, &mut buf) {
        let Ok(line) = std::str::from_utf8(&buf) else {
            return;
        };
        let Ok(op) = parse_line(line) else {
            return;
        };
        match op {
            Op::Insert(v) => assert_eq!(tree.insert(v), model.insert(v), "insert {v:?}"),
            Op::Remove(v) => assert_eq!(tree.remove(v), model.remove(&v), "remove {v:?}"),
            Op::Query(v) => assert_eq!(tree.contains(v), model.contains(&v), "query {v:?}"),
            Op::Skip => {}
        }
        assert_eq!(tree.voxel_count(), model.len() as u64);
        ops += 1;
        if ops > 512 {
            break;
        }
    }
    tree.assert_valid();
});
