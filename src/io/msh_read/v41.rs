//! MSH 4.1 sections: `$Entities` (physical tags of entities), `$Nodes` in entity
//! blocks (optionally with parametric coordinates), `$Elements` in entity blocks; ASCII
//! and binary (`size_t` of 4 or 8 bytes).

use super::{capped, Block, Reader};
use crate::error::Result;
use crate::io::VolumeEntity;

/// A volume entity with its bounding surfaces (orientation signs dropped, sorted).
fn volume_entity(tag: i32, physical: Vec<i32>, mut surfaces: Vec<i32>) -> VolumeEntity {
    for s in surfaces.iter_mut() {
        *s = s.saturating_abs();
    }
    surfaces.sort_unstable();
    surfaces.dedup();
    VolumeEntity {
        tag,
        physical,
        surfaces,
    }
}

impl Reader<'_> {
    pub(super) fn entities_ascii(&mut self) -> Result<()> {
        let c = &mut self.c;
        let max = c.remaining() as u64;
        let counts = [
            c.count("number of points", max)?,
            c.count("number of curves", max)?,
            c.count("number of surfaces", max)?,
            c.count("number of volumes", max)?,
        ];
        for (dim, &n) in counts.iter().enumerate() {
            for _ in 0..n {
                let tag = c.i32("entity tag")?;
                let nbox = if dim == 0 { 3 } else { 6 };
                for _ in 0..nbox {
                    c.f64("entity bounding box")?;
                }
                let nphys = c.count("number of physical tags", max)?;
                let mut physical = Vec::new();
                for _ in 0..nphys {
                    physical.push(c.i32("physical tag")?);
                }
                if nphys == 1 {
                    self.physical.insert((dim as i32, tag), physical[0]);
                }
                if dim > 0 {
                    let nb = c.count("number of bounding entities", max)?;
                    let mut surfaces = Vec::new();
                    for _ in 0..nb {
                        surfaces.push(c.i32("bounding entity tag")?);
                    }
                    if dim == 3 {
                        self.volumes.push(volume_entity(tag, physical, surfaces));
                    }
                }
            }
        }
        Ok(())
    }

    pub(super) fn entities_binary(&mut self) -> Result<()> {
        let ds = self.dsize;
        let c = &mut self.c;
        let mut counts = [0u64; 4];
        for n in counts.iter_mut() {
            *n = c.bin_usize(ds, "entity count")?;
        }
        for (dim, &n) in counts.iter().enumerate() {
            let nbox = if dim == 0 { 3 } else { 6 };
            c.need(n, 4 + 8 * nbox + ds, "entities")?;
            for _ in 0..n {
                let tag = c.bin_i32("entity tag")?;
                c.bytes(8 * nbox, "entity bounding box")?;
                let nphys = c.bin_usize(ds, "number of physical tags")?;
                c.need(nphys, 4, "physical tags")?;
                let mut physical = Vec::new();
                for _ in 0..nphys {
                    physical.push(c.bin_i32("physical tag")?);
                }
                if nphys == 1 {
                    self.physical.insert((dim as i32, tag), physical[0]);
                }
                if dim > 0 {
                    let nb = c.bin_usize(ds, "number of bounding entities")?;
                    c.need(nb, 4, "bounding entity tags")?;
                    let mut surfaces = Vec::new();
                    for _ in 0..nb {
                        surfaces.push(c.bin_i32("bounding entity tag")?);
                    }
                    if dim == 3 {
                        self.volumes.push(volume_entity(tag, physical, surfaces));
                    }
                }
            }
        }
        Ok(())
    }

    pub(super) fn nodes41_ascii(&mut self) -> Result<()> {
        let at = self.c.pos();
        let max = self.c.remaining() as u64;
        let nblocks = self.c.count("number of node blocks", max)?;
        let nnodes = self.c.count("number of nodes", u32::MAX as u64 - 1)?;
        self.c.u64("minimum node tag")?;
        self.c.u64("maximum node tag")?;
        let cap = capped(nnodes, self.c.remaining(), 8);
        let mut tags = Vec::with_capacity(cap);
        self.mesh.nodes.reserve(cap);
        for _ in 0..nblocks {
            let dim = self.c.i32("entity dimension")?;
            self.c.i32("entity tag")?;
            let param = self.c.i32("parametric flag")?;
            let n = self.c.count("number of nodes in block", max)?;
            if tags.len() as u64 + n > nnodes {
                return Err(self
                    .c
                    .err("node blocks hold more nodes than the header says"));
            }
            let extra = if param != 0 {
                dim.clamp(0, 3) as usize
            } else {
                0
            };
            for _ in 0..n {
                tags.push(self.c.u64("node tag")?);
            }
            for _ in 0..n {
                let x = self.c.f64("x coordinate")?;
                let y = self.c.f64("y coordinate")?;
                let z = self.c.f64("z coordinate")?;
                for _ in 0..extra {
                    self.c.f64("parametric coordinate")?;
                }
                self.mesh.nodes.push([x, y, z]);
            }
        }
        if tags.len() as u64 != nnodes {
            return Err(self.c.err(format!(
                "node blocks hold {} nodes but the header says {nnodes}",
                tags.len()
            )));
        }
        self.set_nodes(tags, at)
    }

    pub(super) fn nodes41_binary(&mut self) -> Result<()> {
        let at = self.c.pos();
        let ds = self.dsize;
        let c = &mut self.c;
        let nblocks = c.bin_usize(ds, "number of node blocks")?;
        let nnodes = c.bin_usize(ds, "number of nodes")?;
        c.bin_usize(ds, "minimum node tag")?;
        c.bin_usize(ds, "maximum node tag")?;
        if nnodes >= u32::MAX as u64 {
            return Err(c.err(format!("{nnodes} nodes is more than curvetet supports")));
        }
        c.need(nblocks, 12 + ds, "node blocks")?;
        c.need(nnodes, ds + 24, "nodes")?;
        let mut tags = Vec::with_capacity(nnodes as usize);
        self.mesh.nodes.reserve(nnodes as usize);
        for _ in 0..nblocks {
            let dim = c.bin_i32("entity dimension")?;
            c.bin_i32("entity tag")?;
            let param = c.bin_i32("parametric flag")?;
            let n = c.bin_usize(ds, "number of nodes in block")?;
            // (tags.len() <= nnodes here; `tags.len() + n` could overflow.)
            if n > nnodes - tags.len() as u64 {
                return Err(c.err("node blocks hold more nodes than the header says"));
            }
            let extra = if param != 0 {
                dim.clamp(0, 3) as usize
            } else {
                0
            };
            c.need(n, ds + 24 + 8 * extra, "nodes")?;
            for _ in 0..n {
                tags.push(c.bin_usize(ds, "node tag")?);
            }
            for _ in 0..n {
                let x = c.bin_f64("x coordinate")?;
                let y = c.bin_f64("y coordinate")?;
                let z = c.bin_f64("z coordinate")?;
                c.bytes(8 * extra, "parametric coordinates")?;
                self.mesh.nodes.push([x, y, z]);
            }
        }
        if tags.len() as u64 != nnodes {
            return Err(c.err(format!(
                "node blocks hold {} nodes but the header says {nnodes}",
                tags.len()
            )));
        }
        self.set_nodes(tags, at)
    }

    pub(super) fn elements41_ascii(&mut self) -> Result<()> {
        let max = self.c.remaining() as u64;
        let nblocks = self.c.count("number of element blocks", max)?;
        let nelem = self.c.count("number of elements", max)?;
        self.c.u64("minimum element tag")?;
        self.c.u64("maximum element tag")?;
        let mut total = 0u64;
        let mut raw = [0u64; 128];
        for _ in 0..nblocks {
            let dim = self.c.i32("entity dimension")?;
            let entity = self.c.i32("entity tag")?;
            let ty = self.c.i32("element type")?;
            let n = self.c.count("number of elements in block", max)?;
            let k = self.element_type(ty)?;
            total += n;
            if total > nelem {
                return Err(self
                    .c
                    .err("element blocks hold more elements than the header says"));
            }
            let kind = Self::kind_of(ty);
            if let Some(kind) = kind {
                self.reserve(kind, capped(n, self.c.remaining(), 2 * (k + 1)));
            }
            let start = kind.map(|k| self.kind_len(k));
            for _ in 0..n {
                let etag = self.c.u64("element tag")?;
                if kind.is_some() {
                    for r in raw.iter_mut().take(k) {
                        *r = self.c.u64("node tag")?;
                    }
                    self.eol()?;
                    self.push(ty, &raw[..k], etag, entity)?;
                } else {
                    for _ in 0..k {
                        self.c.u64("node tag")?;
                    }
                    self.eol()?;
                    self.mesh.ignored_elements += 1;
                }
            }
            if let (Some(kind), Some(start)) = (kind, start) {
                let end = self.kind_len(kind);
                self.blocks.push(Block {
                    kind,
                    start,
                    end,
                    dim,
                    entity,
                });
            }
        }
        if total != nelem {
            return Err(self.c.err(format!(
                "element blocks hold {total} elements but the header says {nelem}"
            )));
        }
        Ok(())
    }

    pub(super) fn elements41_binary(&mut self) -> Result<()> {
        let ds = self.dsize;
        let nblocks = self.c.bin_usize(ds, "number of element blocks")?;
        let nelem = self.c.bin_usize(ds, "number of elements")?;
        self.c.bin_usize(ds, "minimum element tag")?;
        self.c.bin_usize(ds, "maximum element tag")?;
        self.c.need(nblocks, 12 + ds, "element blocks")?;
        self.c.need(nelem, 2 * ds, "elements")?;
        let mut total = 0u64;
        let mut raw = [0u64; 128];
        for _ in 0..nblocks {
            let dim = self.c.bin_i32("entity dimension")?;
            let entity = self.c.bin_i32("entity tag")?;
            let ty = self.c.bin_i32("element type")?;
            let n = self.c.bin_usize(ds, "number of elements in block")?;
            let k = self.element_type(ty)?;
            self.c.need(n, (k + 1) * ds, "elements")?;
            total += n;
            if total > nelem {
                return Err(self
                    .c
                    .err("element blocks hold more elements than the header says"));
            }
            let kind = Self::kind_of(ty);
            if let Some(kind) = kind {
                self.reserve(kind, n as usize);
                let start = self.kind_len(kind);
                for _ in 0..n {
                    let etag = self.c.bin_usize(ds, "element tag")?;
                    for r in raw.iter_mut().take(k) {
                        *r = self.c.bin_usize(ds, "node tag")?;
                    }
                    self.push(ty, &raw[..k], etag, entity)?;
                }
                let end = self.kind_len(kind);
                self.blocks.push(Block {
                    kind,
                    start,
                    end,
                    dim,
                    entity,
                });
            } else {
                self.c.bytes(n as usize * (k + 1) * ds, "elements")?;
                self.mesh.ignored_elements += n;
            }
        }
        if total != nelem {
            return Err(self.c.err(format!(
                "element blocks hold {total} elements but the header says {nelem}"
            )));
        }
        Ok(())
    }
}
