//! The HTML page: the packed trees and palette as base64 in a JSON block, and the
//! page's JavaScript and GLSL from `assets/`, embedded at build time.

use base64::Engine as _;
use serde::Serialize;

use super::pack::{PackedTree, MAX_ENTRIES};
use super::{coloured_leaves, Colouring, Palette, ViewError};
use crate::linear::LinearOctree;
use crate::model::Frame;
use crate::Voxel;

const HTML: &str = include_str!("assets/page.html");
const CSS: &str = include_str!("assets/page.css");
const TREE_JS: &str = include_str!("assets/tree.js");
const JS: &str = include_str!("assets/viewer.js");
const VERT: &str = include_str!("assets/quad.vert");
const FRAG: &str = include_str!("assets/trace.frag");

/// The bytes a packed entry takes in the page (4 bytes as base64).
pub const ENTRY_BYTES: f64 = 16.0 / 3.0;

/// The page's size without its data: the HTML, CSS, JavaScript and GLSL, plus room
/// for the metadata.
pub const PAGE_OVERHEAD: u64 =
    (HTML.len() + CSS.len() + JS.len() + VERT.len() + FRAG.len()) as u64 + 16 * 1024;

/// One tree of a page (an animation has several).
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct PageFrame {
    /// What the time slider shows for it (e.g. `t = 0.25 s`).
    pub label: String,
    /// The index of its root entry.
    pub root: u32,
    /// The tree's depth.
    pub depth: u8,
    /// The levels kept (fewer than `depth` when the page shows it coarser).
    pub levels: u8,
    /// Whether it has no black voxel.
    pub empty: bool,
    /// The lowest corner of its space, in voxels.
    pub origin: Voxel,
    /// Its black voxels (of the tree as given, not of the coarser one shown).
    pub voxels: u64,
    /// Its leaves (of the tree as given).
    pub leaves: usize,
    /// The inclusive bounding box of its black voxels, in voxels.
    pub bbox: Option<(Voxel, Voxel)>,
}

/// A page in the making: add trees with [`Page::add`], then write [`Page::html`].
#[derive(Debug, Clone)]
pub struct Page {
    title: String,
    frame: Frame,
    entries: Vec<u32>,
    palette: Palette,
    frames: Vec<PageFrame>,
    notes: Vec<String>,
}

#[derive(Serialize)]
struct Data<'a> {
    title: &'a str,
    voxel_size: f64,
    translate: [f64; 3],
    entries: String,
    entry_count: usize,
    palette: String,
    frames: &'a [PageFrame],
    notes: &'a [String],
}

impl Page {
    /// An empty page: its title, and the world frame its voxels are in.
    #[must_use]
    pub fn new(title: &str, frame: Frame) -> Self {
        Self {
            title: title.to_owned(),
            frame,
            entries: Vec::new(),
            palette: Palette::default(),
            frames: Vec::new(),
            notes: Vec::new(),
        }
    }

    /// How many more entries fit a page of at most `max_bytes` bytes.
    #[must_use]
    pub fn entry_budget(&self, max_bytes: u64) -> usize {
        let used = PAGE_OVERHEAD
            + (self.entries.len() as f64 * ENTRY_BYTES) as u64
            + self.palette.colours().len() as u64 * 4
            + self.frames.len() as u64 * 256;
        let left = max_bytes.saturating_sub(used) as f64 / ENTRY_BYTES;
        (left as usize).min(MAX_ENTRIES - self.entries.len())
    }

    /// Adds `tree` as the next frame, coloured by `colouring`, in at most
    /// `max_entries` more entries: cut short to a coarser depth when it does not
    /// fit (see [`PageFrame::levels`]).
    ///
    /// # Errors
    /// [`ViewError::TooLarge`] when not even its top level fits;
    /// [`ViewError::Palette`] past the palette's size.
    pub fn add(
        &mut self,
        tree: &LinearOctree,
        colouring: Colouring<'_>,
        label: &str,
        max_entries: usize,
    ) -> Result<&PageFrame, ViewError> {
        let leaves = coloured_leaves(tree, colouring, &mut self.palette)?;
        let limit = self.entries.len().saturating_add(max_entries);
        let packed: PackedTree =
            PackedTree::build(&mut self.entries, tree.depth(), &leaves, limit)?;
        self.frames.push(PageFrame {
            label: label.to_owned(),
            root: packed.root,
            depth: packed.depth,
            levels: packed.levels,
            empty: packed.empty,
            origin: tree.origin(),
            voxels: tree.voxel_count(),
            leaves: tree.leaf_count(),
            bbox: tree.bbox(),
        });
        Ok(&self.frames[self.frames.len() - 1])
    }

    /// A line the page shows under its title (e.g. what was reduced to fit).
    pub fn note(&mut self, text: &str) {
        self.notes.push(text.to_owned());
    }

    /// The frames added so far.
    #[must_use]
    pub fn frames(&self) -> &[PageFrame] {
        &self.frames
    }

    /// The packed entries of all frames.
    #[must_use]
    pub fn entries(&self) -> &[u32] {
        &self.entries
    }

    /// The palette.
    #[must_use]
    pub fn palette(&self) -> &Palette {
        &self.palette
    }

    /// The page, one self-contained HTML document.
    #[must_use]
    pub fn html(&self) -> String {
        let b64 = base64::engine::general_purpose::STANDARD;
        let bytes: Vec<u8> = self.entries.iter().flat_map(|e| e.to_le_bytes()).collect();
        let rgb: Vec<u8> = self.palette.colours().iter().flatten().copied().collect();
        let data = Data {
            title: &self.title,
            voxel_size: self.frame.voxel_size,
            translate: self.frame.translate,
            entries: b64.encode(bytes),
            entry_count: self.entries.len(),
            palette: b64.encode(rgb),
            frames: &self.frames,
            notes: &self.notes,
        };
        // `<` only occurs inside JSON strings, where \u003c means the same: no
        // `</script>` can end the block early.
        let json = serde_json::to_string(&data)
            .unwrap_or_default()
            .replace('<', "\\u003c");
        let title = escape_html(&self.title);
        HTML.replace("{{TITLE}}", &title)
            .replace("{{CSS}}", CSS)
            .replace("{{VERT}}", VERT)
            .replace("{{FRAG}}", FRAG)
            .replace("{{TREE_JS}}", TREE_JS)
            .replace("{{JS}}", JS)
            .replace("{{DATA}}", &json)
    }
}

fn escape_html(s: &str) -> String {
    s.replace('&', "&amp;")
        .replace('<', "&lt;")
        .replace('>', "&gt;")
        .replace('"', "&quot;")
}
