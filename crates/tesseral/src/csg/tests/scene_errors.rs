//! Every error path of the scene parser, located, with a hint.

use super::*;

/// Every error path of the parser: (source, line, column, words in the message,
/// words in the hint).
#[test]
fn every_scene_error_is_located_with_a_hint() {
    let cases: &[(&str, usize, usize, &str, &str)] = &[
        (
            "depth 6\ncilinder(r = 1, h = 2)",
            2,
            1,
            "unknown shape or keyword `cilinder`",
            "did you mean `cylinder`",
        ),
        (
            "depth 6\nsphere(radius = 1)",
            2,
            8,
            "has no parameter `radius`",
            "sphere` takes: r",
        ),
        (
            "depth 6\ncylinder(r = 1, hh = 2)",
            2,
            17,
            "no parameter `hh`",
            "did you mean `h`",
        ),
        (
            "depth 6\nsphere()",
            2,
            8,
            "needs the parameter `r`",
            "sphere(r = 10)",
        ),
        (
            "depth 6\nsphere(r = 1, r = 2)",
            2,
            15,
            "given twice",
            "keep one",
        ),
        (
            "depth 6\nsphere(r = -1)",
            2,
            12,
            "must be positive",
            "greater than zero",
        ),
        (
            "depth 6\nsphere(r = [1, 2])",
            2,
            12,
            "must be a number, not a list",
            "brackets",
        ),
        (
            "depth 6\nbox(size = [1, 2])",
            2,
            12,
            "must hold 3 numbers, got 2",
            "[x, y, z]",
        ),
        (
            "depth 6\nsphere(r = 1) at 5",
            2,
            18,
            "must be a list of 3 numbers",
            "[x, y, z]",
        ),
        (
            "depth 6\nsphere(r = 1) at [1, 2, 3] at [1, 2, 3]",
            2,
            28,
            "`at` is given twice",
            "union",
        ),
        (
            "depth 6\nsphere(r = 1) colour \"rde\"",
            2,
            22,
            "unknown colour \"rde\"",
            "did you mean \"red\"",
        ),
        (
            "depth 6\nsphere(r = 1) colour \"#12\"",
            2,
            22,
            "unknown colour",
            "six hex digits",
        ),
        (
            "depth 6\nsphere(r = 1) colour [300, 0, 0]",
            2,
            22,
            "0..=255",
            "[r, g, b]",
        ),
        (
            "depth 6\nsphere(r = 1) scale 0",
            2,
            21,
            "scale must be positive",
            "doubles",
        ),
        (
            "depth 6\nlet radius = 2\nsphere(r = radias)",
            3,
            12,
            "unknown name `radias`",
            "did you mean `radius`",
        ),
        (
            "depth 6\nsphere(r = q)",
            2,
            12,
            "unknown name `q`",
            "let q =",
        ),
        (
            "depth 6\nlet a = 1\nlet a = 2\nsphere(r = a)",
            3,
            5,
            "already defined",
            "line 2",
        ),
        (
            "depth 6\nlet sphere = 1",
            2,
            5,
            "reserved word",
            "another name",
        ),
        (
            "depth 6\nlet 5 = 1",
            2,
            5,
            "expected a name after `let`",
            "let name = value",
        ),
        ("depth 6\nlet a 1", 2, 7, "expected `=`", "let name = value"),
        ("depth 6\nsphere(r = 1 / 0)", 2, 14, "division by zero", ""),
        (
            "depth 6\nsphere(r = [1] * [2])",
            2,
            16,
            "cannot combine",
            "lists of equal length",
        ),
        (
            "depth 6\nsphere(r = \"one\")",
            2,
            12,
            "string is not allowed",
            "colours",
        ),
        (
            "depth 6\nsphere(r = ,)",
            2,
            12,
            "expected a value",
            "a value is a number",
        ),
        (
            "depth 6\nsphere(r = (1)",
            2,
            15,
            "expected `,`",
            "separate parameters",
        ),
        (
            "depth 6\nsphere(r = (1 2))",
            2,
            15,
            "expected `)`",
            "close the parenthesis",
        ),
        (
            "depth 6\nbox(size = [1, 2 3])",
            2,
            18,
            "expected `,`",
            "separate list items",
        ),
        (
            "depth 6\nsphere r = 1",
            2,
            8,
            "expected `(`",
            "sphere(name = value",
        ),
        (
            "depth 6\nsphere(5)",
            2,
            8,
            "expected a parameter name",
            "takes: r",
        ),
        (
            "depth 6\nunion sphere(r = 1)",
            2,
            7,
            "expected `{`",
            "union { ... }",
        ),
        (
            "depth 6\nunion { sphere(r = 1)",
            2,
            22,
            "not closed",
            "line 2",
        ),
        (
            "depth 6\nunion { }",
            2,
            1,
            "group is empty",
            "at least one solid",
        ),
        (
            "depth 6\nnot { sphere(r = 1) sphere(r = 2) }",
            2,
            1,
            "exactly one solid",
            "union",
        ),
        (
            "depth 6\nunion { depth 5 sphere(r = 1) }",
            2,
            9,
            "only allowed at the top level",
            "move it",
        ),
        ("depth 6\nrotate [1, 2, 3]", 2, 1, "must follow a solid", ""),
        (
            "depth 6\n42",
            2,
            1,
            "expected a shape, a group or a setting",
            "statement starts",
        ),
        (
            "depth 6\nsphere(r = 1) @",
            2,
            15,
            "unexpected character `@`",
            "comments start with `#`",
        ),
        (
            "depth 6\nsphere(r = 1) colour \"red",
            2,
            22,
            "unterminated string",
            "close the string",
        ),
        (
            "depth 6\nsphere(r = 1.2.3)",
            2,
            12,
            "is not a number",
            "one decimal point",
        ),
        (
            "depth 6\nsphere(r = 10mm)",
            2,
            12,
            "`10mm` is not a number",
            "units",
        ),
        (
            "depth 0\nsphere(r = 1)",
            1,
            7,
            "whole number from 1 to 16",
            "2^D voxels",
        ),
        ("depth 6.5\nsphere(r = 1)", 1, 7, "whole number", "2^D"),
        (
            "depth 6\ndepth 7\nsphere(r = 1)",
            2,
            1,
            "`depth` is set twice",
            "line 1",
        ),
        (
            "voxel -1\nsphere(r = 1)",
            1,
            7,
            "voxel size must be positive",
            "half a unit",
        ),
        (
            "voxel 0.5\nvoxel 1\nsphere(r = 1)",
            2,
            1,
            "`voxel` is set twice",
            "line 1",
        ),
        (
            "voxel 0.000001\nsphere(r = 1000)",
            1,
            1,
            "more than the limit",
            "larger voxel",
        ),
        (
            "depth 6\nbounds [0, 0, 0] [1, -1, 1]\nsphere(r = 1)",
            2,
            18,
            "must exceed the lower",
            "bounds [xmin",
        ),
        (
            "depth 6\nbounds [0, 0, 0] [1, 1, 1]\nbounds [0, 0, 0] [1, 1, 1]\nsphere(r = 1)",
            3,
            1,
            "`bounds` is set twice",
            "line 2",
        ),
        (
            "depth 6\nvoxel 1\nsphere(r = 1)",
            1,
            1,
            "both `depth` and `voxel`",
            "keep one",
        ),
        (
            "sphere(r = 1)",
            1,
            1,
            "neither `depth` nor `voxel`",
            "depth 8",
        ),
        ("depth 6\n# nothing", 2, 10, "no solid", "sphere(r = 10)"),
        (
            "depth 6\nhalfspace(normal = [0, 0, 1])",
            2,
            1,
            "unbounded",
            "add `bounds",
        ),
        (
            "depth 6\nhalfspace(normal = [0, 0, 0])",
            2,
            20,
            "normal must not be zero",
            "normal = [0, 0, 1]",
        ),
        (
            "depth 6\npolyhedron(planes = 3)",
            2,
            21,
            "must be a list of [nx, ny, nz, d]",
            "planes = [[",
        ),
        (
            "depth 6\npolyhedron(planes = [])",
            2,
            21,
            "`planes` is empty",
            "four planes",
        ),
        (
            "depth 6\npolyhedron(planes = [[0, 0, 0, 1]])",
            2,
            21,
            "zero normal",
            "n·p ≤ d",
        ),
        (
            "depth 6\npolyhedron(planes = [[1, 2, 3]])",
            2,
            21,
            "must hold 4 numbers",
            "[nx, ny, nz, d]",
        ),
        (
            "depth 6\ncone(r1 = 1, r2 = -1, h = 2)",
            2,
            19,
            "`r2` must be zero or positive",
            "pointed cone",
        ),
        (
            "depth 6\ncone(r1 = [1, 2], r2 = 0, h = 2)\ncapsule(r = 1, h = -2)",
            3,
            20,
            "`h` must be zero or positive",
            "end caps",
        ),
        (
            "depth 6\nsphere(r = 1) at [1, 2, 3] + [1, 2]",
            2,
            28,
            "cannot combine",
            "equal length",
        ),
    ];
    for (i, (src, line, col, msg, hint)) in cases.iter().enumerate() {
        let err = match parse(src) {
            Ok(_) => panic!("case {i} parsed: {src:?}"),
            Err(e) => e,
        };
        let d = err
            .diagnostic()
            .unwrap_or_else(|| panic!("case {i}: not a parse error: {err}"));
        assert_eq!((d.line, d.column), (*line, *col), "case {i} {src:?}: {err}");
        assert!(d.message.contains(msg), "case {i}: message {:?}", d.message);
        let h = d.hint.clone().unwrap_or_default();
        assert!(h.contains(hint), "case {i}: hint {h:?}");
        let shown = err.to_string();
        assert!(
            shown.starts_with(&format!("t.tss:{line}:{col}: ")),
            "{shown}"
        );
        assert!(shown.contains('^'), "case {i} has a caret: {shown}");
    }
}

#[test]
fn caret_sits_under_the_fault() {
    let err = parse("depth 6\n  sphere(r = 1) colour \"rde\"\n").unwrap_err();
    let text = err.to_string();
    let lines: Vec<&str> = text.lines().collect();
    assert_eq!(lines[0], "t.tss:2:24: unknown colour \"rde\"");
    assert_eq!(lines[2], "2 |   sphere(r = 1) colour \"rde\"");
    assert_eq!(lines[3], "  |                        ^^^^^");
    assert_eq!(lines[4], "  = hint: did you mean \"red\"?");
}

/// `Scene::with_depth` takes the scene grammar's depths, 1 to 16, and names the
/// range when refused (it said "exceeds the maximum of 21" for 17 and took 0).
#[test]
fn with_depth_names_the_scene_range() {
    let scene = Scene::parse(
        "depth 4\nbox(size = [4, 4, 4])\n",
        std::path::Path::new("s.tss"),
    )
    .unwrap();
    for bad in [0, 17, 30] {
        let err = scene.clone().with_depth(bad).unwrap_err().to_string();
        assert!(
            err.contains(&format!("depth {bad}: a scene's depth is 1 to 16")),
            "{err}"
        );
    }
    let deeper = scene.with_depth(16).unwrap();
    assert_eq!(deeper.depth, 16);
}
