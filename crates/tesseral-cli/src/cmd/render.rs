//! `tesseral render INPUT -o OUT.png`: draws a scene or any octree file.

use std::path::PathBuf;
use std::time::Instant;

use anyhow::{bail, Context, Result};
use tesseral::csg::{Colour, Csg, Scene};
use tesseral::io;
use tesseral::linear::LinearOctree;
use tesseral::render::{self, Camera, Clip, Projection, RenderOptions, View};

use super::budget::Budget;
use super::octree;
use super::output::{self, Size, MAX_SIDE};

mod memory;
mod streamed;

/// Arguments of `tesseral render`.
#[derive(clap::Args)]
pub struct Args {
    /// A scene (`.tss`) or an octree file in any format `tesseral` reads. An octree
    /// file is drawn as it is, never rebuilt.
    input: PathBuf,
    /// The PNG file to write (`-`: standard output).
    #[arg(short, long)]
    output: PathBuf,
    /// Image size, WIDTHxHEIGHT (for a contact sheet: of each view).
    #[arg(long, default_value = "800x600", value_parser = output::parse_size)]
    size: Size,
    /// A named view: iso, front, top or side.
    #[arg(long, default_value = "iso", value_parser = ["iso", "front", "top", "side"])]
    view: String,
    /// Azimuth in degrees (from +x towards +y), overriding the view's.
    #[arg(long, allow_negative_numbers = true)]
    azimuth: Option<f64>,
    /// Elevation in degrees above the horizontal, overriding the view's.
    #[arg(long, allow_negative_numbers = true)]
    elevation: Option<f64>,
    /// Magnification; 1 frames the whole solid.
    #[arg(long, default_value_t = 1.0, allow_negative_numbers = true)]
    zoom: f64,
    /// Perspective projection instead of orthographic.
    #[arg(long)]
    perspective: bool,
    /// Vertical field of view of the perspective camera, degrees (with --perspective).
    #[arg(long, requires = "perspective", allow_negative_numbers = true)]
    fov: Option<f64>,
    /// Draw the outlines of the octree blocks (the decomposition).
    #[arg(long)]
    outline: bool,
    /// No ground plane and no shadows.
    #[arg(long)]
    no_shadows: bool,
    /// Ambient-occlusion rays per pixel (0: none).
    #[arg(long, default_value_t = 0)]
    ao: u32,
    /// Cross-section: `x<C`, `y>C`, ... keeps the part on that side of the plane
    /// (scene units for a scene; for a model file, the world units of its frame,
    /// which are voxels when it has none) and draws the cut faces.
    #[arg(long)]
    cut: Option<String>,
    /// A 2-D slice instead of a 3-D view: `z=C` draws the layer of voxels at C
    /// (scene units for a scene; for a model file, the world units of its frame,
    /// which are voxels when it has none) with its block outlines.
    #[arg(long)]
    slice: Option<String>,
    /// Pixels per voxel of a slice (with --slice). [default: 4]
    #[arg(long, requires = "slice", value_parser = clap::value_parser!(u16).range(1..=4096))]
    slice_scale: Option<u16>,
    /// A contact sheet of the four named views (iso, front, top, side), 2 x 2.
    #[arg(long)]
    sheet: bool,
    /// Background colour, a name or #rrggbb.
    #[arg(long, default_value = "#fafafc")]
    background: String,
    /// Colour of an octree file's solid (a scene's objects carry their own); also
    /// spelled --color.
    #[arg(long, visible_alias = "color", default_value = "#96a5b9")]
    colour: String,
    /// Shading: `faces` shows the blocks' faces, `smooth` the surface's normals (a
    /// scene's own, else estimated from the octree), `auto` picks smooth where voxels
    /// are smaller than two pixels.
    #[arg(long, default_value = "auto")]
    normals: String,
    /// Print sizes and timings as JSON on stdout.
    #[arg(long)]
    json: bool,
    /// Load the whole model before drawing. By default a `.tess` file (either
    /// version) or a dataset is drawn streamed (only the chunks the rays, the cut
    /// or the slice reach are read, within --memory), views, cuts, slices and
    /// contact sheets alike.
    #[arg(long)]
    in_memory: bool,
    #[command(flatten)]
    budget: Budget,
}

/// Parses `x<C`, `x>C` or `x=C`: the axis, the comparison and the value.
fn parse_plane(flag: &str, s: &str) -> Result<(usize, char, f64)> {
    let mut chars = s.trim().chars();
    let axis = match chars.next() {
        Some('x') => 0,
        Some('y') => 1,
        Some('z') => 2,
        _ => bail!(
            "--{flag} {s:?}: expected an axis x, y or z, then <, > or =, then a number (e.g. z<40)"
        ),
    };
    let op = chars.next().unwrap_or(' ');
    if !"<>=".contains(op) {
        bail!("--{flag} {s:?}: expected <, > or = after the axis (e.g. z<40)");
    }
    let value: f64 = chars
        .as_str()
        .trim()
        .parse()
        .with_context(|| format!("--{flag} {s:?}: bad number after {op}"))?;
    if !value.is_finite() {
        bail!("--{flag} {s:?}: the number must be finite");
    }
    Ok((axis, op, value))
}

/// The pixels per voxel of a slice of a tree `side` voxels across, checked
/// against the largest image.
fn slice_scale(args: &Args, side: usize) -> Result<usize> {
    let scale = usize::from(args.slice_scale.unwrap_or(4));
    if side.saturating_mul(scale) > MAX_SIDE {
        bail!(
            "--slice: the tree is {side} voxels across; at {scale} pixels per voxel the image would exceed {MAX_SIDE} pixels (lower --slice-scale)"
        );
    }
    Ok(scale)
}

/// Notes on stderr a `--slice` layer outside the space (`side` voxels from world
/// coordinate `lo` on its axis, `unit` a voxel), whose picture is blank: a blank
/// picture alone looks like a failure.
fn note_slice(spec: &str, layer: i64, side: u64, lo: f64, unit: f64) {
    if layer < 0 || layer as u64 >= side {
        let hi = lo + side as f64 * unit;
        eprintln!(
            "note: --slice '{spec}' lies outside the space ({lo} to {hi} on that axis); the picture is empty"
        );
    }
}

fn parse_colour(flag: &str, s: &str) -> Result<[u8; 3]> {
    Colour::parse(s)
        .map(|c| c.0)
        .with_context(|| format!("--{flag} {s:?}: expected a colour name or #rrggbb"))
}

pub fn run(args: Args) -> Result<()> {
    output::guard("--output", &args.output, &["png"], &[&args.input])?;
    if output::is_stdio(&args.output) && args.json {
        bail!("--json: standard output already holds the picture (-o -)");
    }
    let Size { width, height } = args.size;
    let view = View::parse(&args.view)
        .with_context(|| format!("--view {:?}: expected iso, front, top or side", args.view))?;
    if !(args.zoom.is_finite() && args.zoom > 0.0) {
        bail!("--zoom {}: must be a positive number", args.zoom);
    }
    let fov = args.fov.unwrap_or(40.0);
    if !(fov > 0.0 && fov < 180.0) {
        bail!("--fov {fov}: must lie between 0 and 180 degrees");
    }
    for (flag, value) in [("azimuth", args.azimuth), ("elevation", args.elevation)] {
        if value.is_some_and(|v| !v.is_finite()) {
            bail!(
                "--{flag} {}: must be a finite number of degrees",
                value.unwrap_or_default()
            );
        }
    }
    if args.elevation.is_some_and(|e| e.abs() > 90.0) {
        bail!(
            "--elevation {}: must lie between -90 and 90 degrees",
            args.elevation.unwrap_or_default()
        );
    }
    if args.sheet && (args.slice.is_some() || args.azimuth.is_some() || args.elevation.is_some()) {
        bail!("--sheet draws the four named views: it takes no --slice, --azimuth or --elevation");
    }
    if args.ao > 256 {
        bail!("--ao {}: at most 256 rays per pixel", args.ao);
    }
    let background = parse_colour("background", &args.background)?;
    let solid_colour = parse_colour("colour", &args.colour)?;
    let cut = args
        .cut
        .as_deref()
        .map(|s| parse_plane("cut", s))
        .transpose()?;
    let slice = args
        .slice
        .as_deref()
        .map(|s| parse_plane("slice", s))
        .transpose()?;
    if let Some((_, op, _)) = slice {
        if op != '=' {
            bail!("--slice: write AXIS=C, e.g. z=40");
        }
    }
    if cut.is_some_and(|c| c.1 == '=') {
        bail!("--cut: write AXIS<C or AXIS>C, e.g. z<40");
    }
    let normals = match args.normals.as_str() {
        "auto" => render::Normals::Auto,
        "faces" => render::Normals::Faces,
        "smooth" => render::Normals::Smooth,
        other => bail!("--normals {other:?}: expected auto, faces or smooth"),
    };
    let (az, el) = view.angles();
    let opts = RenderOptions {
        width,
        height,
        camera: Camera {
            azimuth_deg: args.azimuth.unwrap_or(az),
            elevation_deg: args.elevation.unwrap_or(el),
            zoom: args.zoom,
            projection: if args.perspective {
                Projection::Perspective { fov_deg: fov }
            } else {
                Projection::Orthographic
            },
        },
        outline: args.outline,
        shadows: !args.no_shadows,
        ao_samples: args.ao,
        clip: None,
        background,
        normals,
    };
    // Load: a scene is built; an octree file is read as it is.
    let start = Instant::now();
    let is_scene = io::extension(&args.input) == "tss";
    // The picture's pixels (a slice's are known once its tree's side is).
    let view_pixels = memory::picture_pixels(&opts, args.sheet && slice.is_none());
    if !is_scene && !args.in_memory {
        let pixels = if slice.is_some() {
            u64::MAX
        } else {
            view_pixels
        };
        if let Some((tree, (unit, lo))) = streamed::open(&args.input, &args.budget, pixels)? {
            let to_voxel = |a: usize, c: f64| (c - lo[a]) / unit;
            let mode = if let Some((axis, _, c)) = slice {
                let side = 1usize << tree.depth();
                let scale = slice_scale(&args, side)?;
                let at = to_voxel(axis, c).floor() as i64;
                let spec = args.slice.as_deref().unwrap_or_default();
                note_slice(spec, at, side as u64, lo[axis], unit);
                streamed::Mode::Slice { axis, at, scale }
            } else if args.sheet {
                streamed::Mode::Sheet
            } else {
                streamed::Mode::View
            };
            let opts = RenderOptions {
                clip: cut.map(|(axis, op, c)| Clip {
                    axis,
                    at: to_voxel(axis, c),
                    keep_above: op == '>',
                }),
                ..opts
            };
            streamed::check_memory(&args.input, &tree, &mode, &opts, &args.budget)?;
            if let Some(clip) = opts.clip {
                let spec = args.cut.as_deref().unwrap_or_default();
                streamed::note_cut(&tree, clip, spec);
            }
            let out = streamed::Out {
                input: &args.input,
                output: &args.output,
                json: args.json,
            };
            return streamed::draw(&out, &tree, mode, &opts, solid_colour, start);
        }
    }
    // In memory: the picture and, for a .tess file or a dataset, its leaves from
    // its header, before anything is built or read; the tree's own leaves after.
    let hint = if args.in_memory && !is_scene {
        " (without --in-memory a .tess file or a dataset streams)"
    } else {
        ""
    };
    let on_disk = super::streamed::leaves_on_disk(&args.input)?.unwrap_or(0);
    memory::check_drawing(
        &args.input,
        &args.budget,
        on_disk.saturating_mul(memory::FILE_BYTES_PER_LEAF),
        if slice.is_some() { 0 } else { view_pixels },
        hint,
    )?;
    let mut colors = None;
    // A scene's cut and slice positions are in scene units: (scale, lower corner).
    let (tree, csg, (unit, lo)): (LinearOctree, Option<Csg>, (f64, [f64; 3])) = if is_scene {
        let scene = Scene::read(&args.input)?;
        let csg = scene.csg()?;
        // The leaves estimated before the build, as they are counted after it.
        let pixels = match slice {
            Some(_) => {
                let side = 1usize << scene.depth;
                memory::slice_pixels(side as u64, slice_scale(&args, side)?)
            }
            None => view_pixels,
        };
        let tree = args
            .budget
            .build_scene_checked(&args.input, &scene, |leaves| {
                let tree = leaves.saturating_mul(memory::SCENE_BYTES_PER_LEAF);
                memory::check_drawing(&args.input, &args.budget, tree, pixels, hint)
            })?;
        (tree, Some(csg), (scene.voxel, scene.bounds_min))
    } else {
        let model = octree::read(&args.input)?;
        let frame = model.frame;
        colors = model.colors;
        (model.tree, None, (frame.voxel_size, frame.translate))
    };
    let scale = match slice {
        Some(_) => Some(slice_scale(&args, tree.side() as usize)?),
        None => None,
    };
    let per_leaf = if is_scene {
        memory::SCENE_BYTES_PER_LEAF
    } else {
        memory::FILE_BYTES_PER_LEAF
    };
    memory::check_drawing(
        &args.input,
        &args.budget,
        (tree.leaf_count() as u64).saturating_mul(per_leaf),
        scale.map_or(view_pixels, |k| memory::slice_pixels(tree.side(), k)),
        hint,
    )?;
    let to_voxel = |a: usize, c: f64| (c - lo[a]) / unit;
    if let Some((axis, op, c)) = cut {
        // A plane outside the solid keeps all of it or none of it; say which, since
        // an empty picture alone looks like a failure.
        let clip = Clip {
            axis,
            at: to_voxel(axis, c),
            keep_above: op == '>',
        };
        let kept = render::crop_to_clip(&tree, clip).voxel_count();
        let spec = args.cut.as_deref().unwrap_or_default();
        if kept == 0 && !tree.is_empty() {
            eprintln!("note: --cut '{spec}' keeps nothing of the solid; the picture is empty");
        } else if kept == tree.voxel_count() && !tree.is_empty() {
            eprintln!("note: --cut '{spec}' keeps all of the solid (the plane does not cross it)");
        }
    }
    let load_ms = start.elapsed().as_secs_f64() * 1e3;
    let shader = csg
        .as_ref()
        .map(|c| move |p: [f64; 3]| c.colour_at(p).map_or(solid_colour, |k| k.0));
    // An octree file's stored colours: the voxel holding the sample point.
    let stored = colors.as_ref().map(|l| {
        move |p: [f64; 3]| {
            l.get(p.map(|c| c.floor() as i64))
                .map_or(solid_colour, |c| [c[0], c[1], c[2]])
        }
    });
    let fixed = move |_: [f64; 3]| solid_colour;
    let shader_ref: &(dyn Fn([f64; 3]) -> [u8; 3] + Sync) = match (&shader, &stored) {
        (Some(s), _) => s,
        (None, Some(s)) => s,
        (None, None) => &fixed,
    };
    let normal_fn = csg.as_ref().map(|c| move |p: [f64; 3]| c.normal_at(p));
    let surface = render::Surface {
        colour: Some(shader_ref),
        normal: normal_fn
            .as_ref()
            .map(|f| f as &(dyn Fn([f64; 3]) -> Option<[f64; 3]> + Sync)),
    };
    let opts = RenderOptions {
        clip: cut.map(|(axis, op, c)| Clip {
            axis,
            at: to_voxel(axis, c),
            keep_above: op == '>',
        }),
        ..opts
    };
    let start = Instant::now();
    let image = if let (Some((axis, _, c)), Some(scale)) = (slice, scale) {
        let layer = to_voxel(axis, c).floor() as i64;
        let spec = args.slice.as_deref().unwrap_or_default();
        note_slice(spec, layer, tree.side(), lo[axis], unit);
        render::section(&tree, surface, axis, layer, scale)
    } else if args.sheet {
        render::contact_sheet(&tree, surface, &opts, &View::ALL, 2)
    } else {
        render::render(&tree, surface, &opts)
    };
    let render_ms = start.elapsed().as_secs_f64() * 1e3;
    if output::is_stdio(&args.output) {
        super::stdio::to_stdout("png", |p| {
            image.write_png(p).map_err(|e| anyhow::anyhow!("{e}"))
        })?;
    } else {
        image
            .write_png(&args.output)
            .with_context(|| format!("writing {}", args.output.display()))?;
    }
    if args.json {
        let out = serde_json::json!({
            "input": args.input,
            "output": args.output,
            "width": image.width,
            "height": image.height,
            "depth": tree.depth(),
            "leaves": tree.leaf_count(),
            "voxels": tree.voxel_count(),
            "rebuilt_from_scene": is_scene,
            "streamed": false,
            "load_ms": load_ms,
            "render_ms": render_ms,
        });
        crate::outln!("{out}")?;
    }
    Ok(())
}
