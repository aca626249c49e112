//! Start shapes of a chain by name: `voxel`, or `box:AxBxC`.

use super::RsmcError;
use crate::Voxel;

/// The longest side of a `box:` start shape.
pub const MAX_BOX_SIDE: u64 = 1000;
/// The most voxels a named start shape may hold.
pub const MAX_START_VOXELS: u64 = 10_000_000;

/// The voxels of the start shape named `s`: `voxel` (one voxel at the origin) or
/// `box:AxBxC` (A×B×C voxels with a corner at the origin, sides 1 to
/// [`MAX_BOX_SIDE`], at most [`MAX_START_VOXELS`] in all, checked before any is made).
///
/// # Errors
/// [`RsmcError::InvalidParameter`] naming the shape and what is wrong with it.
///
/// ```
/// use tesseral::rsmc::parse_start;
/// assert_eq!(parse_start("voxel").unwrap(), vec![[0, 0, 0]]);
/// assert_eq!(parse_start("box:2x1x1").unwrap(), vec![[0, 0, 0], [1, 0, 0]]);
/// assert!(parse_start("box:0x1x1").is_err());
/// ```
pub fn parse_start(s: &str) -> Result<Vec<Voxel>, RsmcError> {
    let bad = |why: String| RsmcError::InvalidParameter(format!("start {s:?}: {why}"));
    if s == "voxel" {
        return Ok(vec![[0, 0, 0]]);
    }
    let Some(dims) = s.strip_prefix("box:") else {
        return Err(bad("expected `voxel` or `box:AxBxC`".into()));
    };
    let parts: Vec<&str> = dims.split('x').collect();
    if parts.len() != 3 {
        return Err(bad("expected three sizes, as in box:3x2x1".into()));
    }
    let mut d = [0u64; 3];
    for (k, p) in parts.iter().enumerate() {
        d[k] = p
            .parse()
            .map_err(|_| bad(format!("size {p:?} is not a number")))?;
        if !(1..=MAX_BOX_SIDE).contains(&d[k]) {
            return Err(bad(format!("box sizes must be 1 to {MAX_BOX_SIDE}")));
        }
    }
    if d[0] * d[1] * d[2] > MAX_START_VOXELS {
        return Err(bad(format!("more than {MAX_START_VOXELS} voxels")));
    }
    let mut v = Vec::with_capacity((d[0] * d[1] * d[2]) as usize);
    for z in 0..d[2] as i64 {
        for y in 0..d[1] as i64 {
            for x in 0..d[0] as i64 {
                v.push([x, y, z]);
            }
        }
    }
    Ok(v)
}

#[cfg(test)]
mod tests {
    use super::*;
    use std::collections::HashSet;

    #[test]
    fn boxes_hold_every_voxel_once() {
        for (a, b, c) in [(1, 1, 1), (3, 2, 1), (1, 4, 5), (7, 7, 7)] {
            let v = parse_start(&format!("box:{a}x{b}x{c}")).unwrap();
            let set: HashSet<Voxel> = v.iter().copied().collect();
            assert_eq!(v.len(), (a * b * c) as usize);
            assert_eq!(set.len(), v.len());
            assert!(v.iter().all(|p| (0..a).contains(&p[0])
                && (0..b).contains(&p[1])
                && (0..c).contains(&p[2])));
        }
    }

    #[test]
    fn bad_shapes_say_what_is_wrong() {
        for (s, why) in [
            ("ball", "expected `voxel`"),
            ("box:3x2", "three sizes"),
            ("box:3x2x1x1", "three sizes"),
            ("box:3xax1", "not a number"),
            ("box:0x1x1", "1 to 1000"),
            ("box:1001x1x1", "1 to 1000"),
            ("box:1000x1000x11", "more than 10000000"),
        ] {
            let e = parse_start(s).unwrap_err().to_string();
            assert!(e.contains(why) && e.contains(s), "{s}: {e}");
        }
    }
}
