#![no_main]
//! Fuzzes `simulate`'s world file: the input is written as `world.json` into a
//! private folder holding two tiny octrees (`a.xyz`, `b.tss`), read within a small
//! leaf budget (paths may not leave the folder), and a world that reads is simulated
//! for at most 20 steps.
use libfuzzer_sys::fuzz_target;
use std::ops::ControlFlow;
use std::path::PathBuf;
use std::sync::OnceLock;
use tesseral::motion::read_world_limited;

fn folder() -> &'static PathBuf {
    static DIR: OnceLock<PathBuf> = OnceLock::new();
    DIR.get_or_init(|| {
        let dir = std::env::temp_dir().join(format!("tesseral-fuzz-world-{}", std::process::id()));
        std::fs::create_dir_all(&dir).expect("fuzz folder");
        std::fs::write(dir.join("a.xyz"), "0 0 0\n1 0 0\n0 1 0\n").expect("a.xyz");
        std::fs::write(dir.join("b.tss"), "depth 3\nsphere(r = 3)\n").expect("b.tss");
        dir
    })
}

fuzz_target!(|data: &[u8]| {
    let path = folder().join("world.json");
    std::fs::write(&path, data).expect("world.json");
    let Ok(wf) = read_world_limited(&path, 10_000, false) else {
        return;
    };
    if wf.world.objects.len() > 16 {
        return;
    }
    let steps = wf.steps.min(20);
    let mut frames = 0;
    let _ = wf.world.simulate_each(wf.time_step, steps, true, |_| {
        frames += 1;
        ControlFlow::Continue(())
    });
});
