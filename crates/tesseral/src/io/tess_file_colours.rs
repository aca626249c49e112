//! The colours of a [`TessFile`]: its colour regions as streams, and the blocks
//! of its colour index (see `io/colour_index.rs`) decoded one at a time.

use super::tess_file::{release_map, Body, LeafIter};
use super::{FormatError, TessFile};
use crate::linear::Leaf;

impl TessFile {
    /// The colour index of a version-2 file whose only layer is colours.
    pub(crate) fn colour_only_index(&self) -> Option<&super::colour_index::ColourIndex> {
        match &self.body {
            Body::Chunked(b, l) => {
                let flags = u16::from_le_bytes([b[l.sections.0], b[l.sections.0 + 1]]);
                let only =
                    flags & (super::sections::FLAG_FREE | super::sections::FLAG_LOG_ODDS) == 0;
                l.colour_index.as_ref().filter(|_| only)
            }
            _ => None,
        }
    }

    /// Block `k` of the colour index's blocks (of region `i`), decoded and
    /// checked ([`super::colour_index::decode_block`]).
    pub(crate) fn colour_block(&self, i: usize, k: usize) -> Result<Vec<Leaf>, FormatError> {
        match (&self.body, self.colour_only_index()) {
            (Body::Chunked(b, l), Some(ix)) => {
                super::colour_index::decode_block(b, ix, i, k, l.depth)
                    .map_err(|m| FormatError::corrupt(m).with_path(&self.path))
            }
            _ => Err(FormatError::corrupt("no colour index").with_path(&self.path)),
        }
    }

    /// Every block of the colour index, decoded and checked one at a time as a
    /// streamed render reads them, with the colour of its region; `None` when the
    /// file has no colour index (or layers other than colours). O(colour bytes).
    #[must_use]
    pub fn indexed_colour_blocks(
        &self,
    ) -> Option<impl Iterator<Item = (crate::model::Rgba, Result<Vec<Leaf>, FormatError>)> + '_>
    {
        let ix = self.colour_only_index()?;
        Some(ix.regions.iter().enumerate().flat_map(move |(i, r)| {
            (r.blocks.0..r.blocks.1).map(move |k| (r.rgba, self.colour_block(i, k)))
        }))
    }

    /// The colour regions as streams of leaves, decoded as they are read, for a
    /// file whose only layer is colours, opened streaming if it is version 1;
    /// `None` when it has other layers, when it is version 1 opened whole, or when
    /// it is version 1 and a region is not canonical (it holds eight sibling
    /// leaves in a row, which the whole-file reader merges; checked once, in
    /// O(colour bytes)): read it with [`TessFile::to_model`].
    ///
    /// # Errors
    /// [`FormatError::Corrupt`] for a bad colour section.
    pub fn colour_streams(
        &self,
    ) -> Result<Option<Vec<(crate::model::Rgba, super::RegionLeaves<'_>)>>, FormatError> {
        match &self.body {
            Body::Chunked(bytes, layout) if self.colour_only_index().is_some() => {
                let ix = layout.colour_index.as_ref().expect("an index");
                self.colours_checked
                    .get_or_init(|| {
                        let r = super::colour_index::verify_crcs(bytes, ix);
                        if let Some(first) = ix.regions.first() {
                            release_map(bytes, first.start, ix.start);
                        }
                        r
                    })
                    .clone()
                    .map_err(|m| FormatError::corrupt(m).with_path(&self.path))?;
                Ok(Some(
                    ix.regions
                        .iter()
                        .map(|r| {
                            let span = (r.start, r.end);
                            (
                                r.rgba,
                                super::RegionLeaves::region(bytes, span, r.count, layout.depth),
                            )
                        })
                        .collect(),
                ))
            }
            Body::Chunked(bytes, layout) => super::tess_colours::colour_regions(
                bytes,
                layout.sections,
                layout.depth,
                &|a, b| {
                    release_map(bytes, a, b);
                },
            )
            .map_err(|m| FormatError::corrupt(m).with_path(&self.path)),
            Body::Payload(bytes, x) => {
                let regions = super::tess_colours::colour_regions_flagged(
                    bytes,
                    x.flags,
                    x.sections,
                    x.depth,
                    &|a, b| {
                        release_map(bytes, a, b);
                    },
                )
                .map_err(|m| FormatError::corrupt(m).with_path(&self.path))?;
                // The whole-file reader merges a region's complete sibling octets
                // (which no writer leaves); such a layer is read whole, so that the
                // streams never differ from the decoded regions.
                let canonical = *x.colours_canonical.get_or_init(|| {
                    regions
                        .iter()
                        .flatten()
                        .all(|(_, r)| crate::linear::is_canonical_stream(r.clone()))
                });
                Ok(regions.filter(|_| canonical))
            }
            Body::Decoded(_) => Ok(None),
        }
    }

    /// The colour regions as streams of leaves, for a file whose only layer is
    /// colours, whatever its version: a version-2 file's regions are decoded as
    /// they are read ([`TessFile::colour_streams`]); a version-1 file was decoded
    /// whole at [`TessFile::open`] and its regions are walked in memory. `None`
    /// when the file has free space or log-odds.
    ///
    /// # Errors
    /// [`FormatError::Corrupt`] for a bad colour section.
    pub fn colour_leaves(
        &self,
    ) -> Result<Option<Vec<(crate::model::Rgba, LeafIter<'_>)>>, FormatError> {
        match &self.body {
            Body::Chunked(..) | Body::Payload(..) => Ok(self.colour_streams()?.map(|v| {
                v.into_iter()
                    .map(|(c, r)| (c, Box::new(r) as LeafIter<'_>))
                    .collect()
            })),
            Body::Decoded(_) => {
                if self.extras.free.is_some() || self.extras.log_odds.is_some() {
                    return Ok(None);
                }
                let regions = self.extras.colors.as_ref().map_or(&[][..], |l| l.regions());
                Ok(Some(
                    regions
                        .iter()
                        .map(|(c, t)| {
                            (
                                *c,
                                Box::new(t.leaves().iter().copied().map(Ok)) as LeafIter<'_>,
                            )
                        })
                        .collect(),
                ))
            }
        }
    }
}
