//! `tesseral view FILE|SCENE -o view.html`: one self-contained page (WebGL2) that
//! draws the octree by casting rays through it on the GPU; see docs/view.md.
//! `simulate --view` and `rsmc --view` use [`write_page`] for their animations.

use std::path::{Path, PathBuf};
use std::time::Instant;

use anyhow::{bail, Context, Result};
use tesseral::csg::Colour;
use tesseral::view::{Colouring, Page, PageFrame};

use super::budget::Budget;
use super::octree;
use super::output::{self, human_bytes, parse_bytes};

/// The default `--max-page`: a depth-10 scene of 1.7 M leaves fits.
pub const DEFAULT_MAX_PAGE: &str = "20M";

/// The page-size flags of every command that writes a viewer page.
#[derive(clap::Args, Clone, Copy, Debug)]
pub struct PageArgs {
    /// The largest page to write: bytes, or a number with K, M or G (powers of 1024).
    /// A tree that does not fit is shown at a coarser depth (the page says so),
    /// unless --exact.
    #[arg(long, value_name = "SIZE", default_value = DEFAULT_MAX_PAGE, value_parser = parse_bytes)]
    pub max_page: u64,
    /// Refuse a tree that does not fit --max-page instead of showing it coarser.
    #[arg(long)]
    pub exact: bool,
}

/// Arguments of `tesseral view`.
#[derive(clap::Args)]
pub struct Args {
    /// A scene (`.tss`, built with its objects' colours) or an octree file in any
    /// format `tesseral` reads (drawn with its stored colours, if any).
    input: PathBuf,
    /// The page to write (`.html`).
    #[arg(short, long)]
    output: PathBuf,
    /// Colour of voxels without one of their own (an octree file without colours);
    /// also spelled --color.
    #[arg(long, visible_alias = "color", default_value = "#96a5b9")]
    colour: String,
    /// Print the page's size, depth and timings as JSON on stdout.
    #[arg(long)]
    json: bool,
    #[command(flatten)]
    page: PageArgs,
    #[command(flatten)]
    budget: Budget,
}

/// Memory per leaf of making the page beside the model: the leaves packed and
/// coloured, the page's text (measured: 82–90 bytes beyond the model on the
/// showcase and the spheroid at depth 10).
const PAGE_BYTES_PER_LEAF: u64 = 96;

pub fn run(args: Args) -> Result<()> {
    output::guard("--output", &args.output, &["html"], &[&args.input])?;
    if output::is_stdio(&args.output) {
        bail!("--output: write the page to a file (name.html), not standard output");
    }
    let colour = Colour::parse(&args.colour).map(|c| c.0).with_context(|| {
        format!(
            "--colour {:?}: expected a colour name or #rrggbb",
            args.colour
        )
    })?;
    let start = Instant::now();
    let budget = args.budget.for_work(PAGE_BYTES_PER_LEAF);
    let model = octree::read_model(&args.input, &budget, &Default::default())?;
    let load_ms = start.elapsed().as_secs_f64() * 1e3;
    let start = Instant::now();
    let title = args.input.file_name().map_or_else(
        || args.input.display().to_string(),
        |n| n.to_string_lossy().into_owned(),
    );
    let mut page = Page::new(&title, model.frame);
    let colouring = match &model.colors {
        Some(layer) => Colouring::Layer(layer, colour),
        None => Colouring::Fixed(colour),
    };
    let budget = page.entry_budget(args.page.max_page);
    let frame = page
        .add(&model.tree, colouring, &title, budget)
        .map_err(|e| too_large(&args.page, &e.to_string()))?
        .clone();
    reduced_note(&mut page, &args.page, std::slice::from_ref(&frame))?;
    let pack_ms = start.elapsed().as_secs_f64() * 1e3;
    let bytes = write_page(&page, &args.output, &args.page)?;
    if args.json {
        let out = serde_json::json!({
            "input": args.input,
            "output": args.output,
            "page_bytes": bytes,
            "max_page": args.page.max_page,
            "depth": frame.depth,
            "shown_depth": frame.levels,
            "leaves": frame.leaves,
            "voxels": frame.voxels,
            "entries": page.entries().len(),
            "colours": page.palette().colours().len(),
            // The spelling of every other command's key; `colours` kept.
            "colors": page.palette().colours().len(),
            "load_ms": load_ms,
            "pack_ms": pack_ms,
        });
        crate::outln!("{out}")?;
    }
    Ok(())
}

fn too_large(args: &PageArgs, why: &str) -> anyhow::Error {
    anyhow::anyhow!(
        "the page would exceed --max-page {} ({why}); raise --max-page",
        human_bytes(args.max_page)
    )
}

/// Notes on the page when any frame is shown coarser than it is, or refuses that
/// under `--exact`.
///
/// # Errors
/// Under `--exact`, an error naming the limit and the depth that would fit.
pub fn reduced_note(page: &mut Page, args: &PageArgs, frames: &[PageFrame]) -> Result<()> {
    let Some(worst) = frames
        .iter()
        .filter(|f| f.levels < f.depth)
        .min_by_key(|f| f.levels)
    else {
        return Ok(());
    };
    if args.exact {
        bail!(
            "the octree (depth {}, {} leaves) does not fit a page of --max-page {}: at most depth {} would; \
             raise --max-page, or leave out --exact to show it at depth {}",
            worst.depth,
            worst.leaves,
            human_bytes(args.max_page),
            worst.levels,
            worst.levels
        );
    }
    page.note(&format!(
        "Shown at depth {} of {} (each shown voxel is {} voxels across, black where any of them is) to fit --max-page {}.",
        worst.levels,
        worst.depth,
        1u64 << (worst.depth - worst.levels),
        human_bytes(args.max_page)
    ));
    Ok(())
}

/// Writes `page` to `path` atomically, after checking its size against
/// `--max-page`; returns its size in bytes.
///
/// # Errors
/// Over the limit, or the write's error naming the file.
pub fn write_page(page: &Page, path: &Path, args: &PageArgs) -> Result<u64> {
    let html = page.html();
    let bytes = html.len() as u64;
    if bytes > args.max_page {
        bail!(
            "{}: the page would be {} ({bytes} bytes), more than --max-page {}; raise --max-page",
            path.display(),
            human_bytes(bytes),
            human_bytes(args.max_page)
        );
    }
    tesseral::io::write_atomic(path, |w| w.write_all(html.as_bytes()))
        .with_context(|| format!("writing {}", path.display()))?;
    Ok(bytes)
}

/// The most frames an animation page holds; longer runs keep every k-th step.
pub const MAX_FRAMES: u64 = 240;

/// An animation page in the making (`simulate --view`, `rsmc --view`): frames are
/// added as the run produces them, each within its share of `--max-page`.
pub struct Animation {
    page: Page,
    args: PageArgs,
    every: u64,
    expected: u64,
    added: u64,
    offered: u64,
    shown: Vec<PageFrame>,
}

impl Animation {
    /// A page to write at `path` (titled by its name) for a run of about `count`
    /// frames.
    pub fn for_file(path: &Path, frame: tesseral::Frame, args: PageArgs, count: u64) -> Self {
        let title = path
            .file_stem()
            .map_or_else(String::new, |s| s.to_string_lossy().into_owned());
        Self::new(&title, frame, args, count)
    }

    /// A page for a run of `count` frames (steps, sweeps).
    pub fn new(title: &str, frame: tesseral::Frame, args: PageArgs, count: u64) -> Self {
        let every = count.div_ceil(MAX_FRAMES).max(1);
        let mut page = Page::new(title, frame);
        if every > 1 {
            page.note(&format!(
                "{count} frames: every {every}th is shown (at most {MAX_FRAMES})."
            ));
        }
        Self {
            page,
            args,
            every,
            expected: count.div_ceil(every),
            added: 0,
            offered: 0,
            shown: Vec::new(),
        }
    }

    /// Whether frame `index` (from 0) goes into the page.
    pub fn wants(&self, index: u64) -> bool {
        index % self.every == 0
    }

    /// Offers the next frame of a run as voxels in one colour, with its label; it
    /// is kept when its turn comes, or when it is the `last`.
    ///
    /// # Errors
    /// As [`Animation::add`].
    pub fn offer_voxels(
        &mut self,
        last: bool,
        frame: impl FnOnce() -> (Vec<tesseral::Voxel>, String),
    ) -> Result<()> {
        let index = self.offered;
        self.offered += 1;
        if !(last || self.wants(index)) {
            return Ok(());
        }
        let (voxels, label) = frame();
        let tree = tesseral::LinearOctree::from_voxels_fitted(&voxels)
            .context("building the octree to view")?;
        let colour = Colouring::Fixed(tesseral::render::DEFAULT_COLOUR);
        self.add(&tree, colour, &label)
    }

    /// Adds the next frame kept, with its label.
    ///
    /// # Errors
    /// When not even its top level fits its share of the page.
    pub fn add(
        &mut self,
        tree: &tesseral::LinearOctree,
        colouring: Colouring<'_>,
        label: &str,
    ) -> Result<()> {
        let left = self.expected.saturating_sub(self.added).max(1);
        let share = self.page.entry_budget(self.args.max_page) / left as usize;
        let f = self
            .page
            .add(tree, colouring, label, share)
            .map_err(|e| too_large(&self.args, &e.to_string()))?
            .clone();
        self.shown.push(f);
        self.added += 1;
        Ok(())
    }

    /// Writes the page (after the notes on any frame shown coarser); returns its size.
    ///
    /// # Errors
    /// Under `--exact` when a frame was shown coarser; the write's errors.
    pub fn finish(mut self, path: &Path) -> Result<u64> {
        if self.shown.is_empty() {
            bail!("{}: no frame to show", path.display());
        }
        let shown = std::mem::take(&mut self.shown);
        reduced_note(&mut self.page, &self.args, &shown)?;
        write_page(&self.page, path, &self.args)
    }
}
