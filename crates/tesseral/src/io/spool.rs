//! Layers written while a `.tess` file streams: each region's leaves go to a
//! temporary file as they come ([`LeafSpool`]), and [`TessWriter::finish_spooled`]
//! copies them into the colour section at the end. The section has the layout an
//! in-memory [`crate::model::Layer`] is written with, so every reader reads it.

use std::fs::File;
use std::io::{self, BufWriter, Read, Seek, Write};
use std::path::Path;

use super::chunked::{TessWriter, MERGE_TAIL};
use super::colour_index::{IndexBuilder, FLAG_COLOUR_INDEX, INDEX_BLOCK};
use super::leafstream::put_varint;
use super::sections::{put_sections, Sections, FLAG_COLOR_LAYER};
use crate::linear::{push_merging, Leaf};
use crate::model::{Frame, LayerValue, Rgba};

/// Leaves held before the oldest are written out.
const SPOOL_BATCH: usize = 1 << 14;

/// The leaves of one region, in tesseral order, merged into maximal blocks as they
/// come and written to an unnamed temporary file (gone when dropped), holding at
/// most a batch of them in memory.
pub struct LeafSpool {
    file: BufWriter<File>,
    pending: Vec<Leaf>,
    prev: u64,
    prev_end: u64,
    written: u64,
    bytes: Vec<u8>,
}

impl LeafSpool {
    /// A spool whose temporary file lies in `dir`.
    ///
    /// # Errors
    /// When the temporary file cannot be made.
    pub fn new_in(dir: &Path) -> io::Result<Self> {
        Ok(Self {
            file: BufWriter::new(tempfile::tempfile_in(dir)?),
            pending: Vec::new(),
            prev: 0,
            prev_end: 0,
            written: 0,
            bytes: Vec::new(),
        })
    }

    /// Adds the next leaf; it must start at or after the end of the one before.
    ///
    /// # Errors
    /// A write error of the temporary file.
    pub fn push(&mut self, leaf: Leaf) -> io::Result<()> {
        push_merging(&mut self.pending, leaf);
        if self.pending.len() >= SPOOL_BATCH + MERGE_TAIL {
            self.write_out(SPOOL_BATCH)?;
        }
        Ok(())
    }

    /// One past the last voxel code pushed (0 before any).
    #[must_use]
    pub fn last_end(&self) -> u64 {
        self.pending.last().map_or(self.prev_end, |l| l.end())
    }

    /// The leaves so far (merged).
    #[must_use]
    pub fn leaf_count(&self) -> u64 {
        self.written + self.pending.len() as u64
    }

    fn write_out(&mut self, n: usize) -> io::Result<()> {
        self.bytes.clear();
        for l in self.pending.drain(..n) {
            put_varint(&mut self.bytes, l.packed() - self.prev);
            self.prev = l.packed();
            self.prev_end = l.end();
        }
        self.written += n as u64;
        self.file.write_all(&self.bytes)
    }

    /// Writes what is held and gives back the leaf count and the file, rewound.
    fn finish(mut self) -> io::Result<(u64, File)> {
        self.write_out(self.pending.len())?;
        let mut f = self
            .file
            .into_inner()
            .map_err(io::IntoInnerError::into_error)?;
        f.rewind()?;
        Ok((self.written, f))
    }
}

impl<W: Write> TessWriter<W> {
    /// As [`TessWriter::finish`], with a colour section made of `colours`: one spool
    /// of leaves per colour, disjoint, each within the leaves pushed. Colours with no
    /// leaves are left out; none at all writes no colour section.
    ///
    /// # Errors
    /// Any error of the writer or the spools' files; [`io::ErrorKind::InvalidInput`]
    /// when a colour is given twice.
    pub fn finish_spooled(self, frame: Frame, colours: Vec<(Rgba, LeafSpool)>) -> io::Result<W> {
        self.finish_spooled_with(frame, colours, false)
    }

    /// As [`TessWriter::finish_spooled`], but the colour section is written even
    /// when no colour has leaves: an empty colour layer, as the in-memory writer
    /// writes a model whose colour layer is present and empty (the translation of a
    /// coloured file keeps its layer, as [`crate::model::Model::translate`] does).
    ///
    /// # Errors
    /// As [`TessWriter::finish_spooled`].
    pub fn finish_spooled_layer(
        self,
        frame: Frame,
        colours: Vec<(Rgba, LeafSpool)>,
    ) -> io::Result<W> {
        self.finish_spooled_with(frame, colours, true)
    }

    fn finish_spooled_with(
        self,
        frame: Frame,
        colours: Vec<(Rgba, LeafSpool)>,
        keep_layer: bool,
    ) -> io::Result<W> {
        let mut regions = Vec::new();
        for (c, s) in colours {
            if s.leaf_count() > 0 {
                regions.push((c, s.finish()?));
            }
        }
        regions.sort_unstable_by_key(|(c, _)| c.key());
        let block = self.colour_block;
        if regions.windows(2).any(|w| w[0].0 == w[1].0) {
            return Err(io::Error::new(
                io::ErrorKind::InvalidInput,
                "a colour is given twice",
            ));
        }
        self.finish_with(|emit| {
            let mut head = vec![0, 0];
            let mut flags = put_sections(&mut head, &Sections::frame(frame));
            if keep_layer || !regions.is_empty() {
                flags |= FLAG_COLOR_LAYER;
                head.extend_from_slice(&(regions.len() as u64).to_le_bytes());
            }
            let indexed = block.is_some() && !regions.is_empty();
            if indexed {
                flags |= FLAG_COLOUR_INDEX;
            }
            head[..2].copy_from_slice(&flags.to_le_bytes());
            emit(&head)?;
            // The colour index is made as the regions' bytes go by.
            let mut at = head.len() as u64;
            let mut index = IndexBuilder::new(block.unwrap_or(INDEX_BLOCK));
            let mut buf = vec![0u8; 1 << 20];
            for (c, (count, file)) in &mut regions {
                let (c, count) = (*c, *count);
                let mut region = c.to_vec();
                region.extend_from_slice(&count.to_le_bytes());
                emit(&region)?;
                at += region.len() as u64;
                index.region(c, count, at);
                loop {
                    let n = file.read(&mut buf)?;
                    if n == 0 {
                        break;
                    }
                    index.feed(&buf[..n]);
                    at += n as u64;
                    emit(&buf[..n])?;
                }
            }
            if indexed {
                emit(&index.finish())?;
            }
            Ok(())
        })
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::io::{native, TessFile};
    use crate::linear::LinearOctree;
    use crate::model::{Layer, Model};

    /// A file finished with spooled colours reads back as the model written in
    /// memory with the same layer: same bytes, once the chunking agrees.
    #[test]
    fn spooled_colours_write_the_in_memory_layer() {
        let dir = tempfile::tempdir().unwrap();
        let tree = LinearOctree::from_voxels(
            5,
            [0, 0, 0],
            (0..32).flat_map(|x| (0..20).map(move |y| [x, y, (x * y) % 7])),
        )
        .unwrap();
        let (red, blue) = ([255, 0, 0, 255], [0, 0, 255, 255]);
        let half = |keep_low: bool| {
            LinearOctree::from_sorted_leaves(
                5,
                [0, 0, 0],
                tree.leaves()
                    .iter()
                    .copied()
                    .filter(|l| (l.code() < 9000) == keep_low),
            )
            .unwrap()
        };
        let layer =
            Layer::from_regions(5, [0, 0, 0], [(blue, half(false)), (red, half(true))]).unwrap();
        let frame = Frame::new(0.5, [1.0, 2.0, 3.0]);
        let model = Model {
            colors: Some(layer.clone()),
            ..Model::new(tree.clone()).with_frame(frame)
        };
        let mut w = TessWriter::new(Vec::new(), 5, [0, 0, 0])
            .unwrap()
            .with_chunk_leaves(50);
        // Give the spools unmerged voxels: they merge them.
        let mut spools = vec![
            (red, LeafSpool::new_in(dir.path()).unwrap()),
            (blue, LeafSpool::new_in(dir.path()).unwrap()),
            ([1, 2, 3, 255], LeafSpool::new_in(dir.path()).unwrap()),
        ];
        for &l in tree.leaves() {
            w.push(l).unwrap();
            let s = if l.code() < 9000 { 0 } else { 1 };
            for v in l.code()..l.end() {
                spools[s].1.push(Leaf::new(v, 0)).unwrap();
            }
        }
        let bytes = w.finish_spooled(frame, spools).unwrap();
        let back = native::decode(&bytes).unwrap();
        assert_eq!(back, model);
        let f = TessFile::from_bytes(bytes, Path::new("x.tess")).unwrap();
        assert_eq!(f.to_model().unwrap(), model);
        back.colors.unwrap().assert_valid();
    }
}
