//! MSH 2.2 (and 2.0, 2.1) sections: `$Nodes` and `$Elements` with per-element tags
//! (physical, elementary, ...); ASCII and binary (element blocks of one type).

use super::{capped, Reader};
use crate::error::Result;

impl Reader<'_> {
    pub(super) fn nodes2(&mut self) -> Result<()> {
        let at = self.c.pos();
        let n = self.c.count("number of nodes", u32::MAX as u64 - 1)?;
        let mut tags;
        if self.binary {
            self.c.rest_of_line();
            let c = &mut self.c;
            c.need(n, 28, "nodes")?;
            tags = Vec::with_capacity(n as usize);
            self.mesh.nodes.reserve(n as usize);
            for _ in 0..n {
                let t = c.bin_i32("node tag")?;
                let t = u64::try_from(t).map_err(|_| c.err(format!("negative node tag {t}")))?;
                tags.push(t);
                let x = c.bin_f64("x coordinate")?;
                let y = c.bin_f64("y coordinate")?;
                let z = c.bin_f64("z coordinate")?;
                self.mesh.nodes.push([x, y, z]);
            }
        } else {
            let cap = capped(n, self.c.remaining(), 8);
            tags = Vec::with_capacity(cap);
            self.mesh.nodes.reserve(cap);
            for _ in 0..n {
                tags.push(self.c.u64("node tag")?);
                let x = self.c.f64("x coordinate")?;
                let y = self.c.f64("y coordinate")?;
                let z = self.c.f64("z coordinate")?;
                self.mesh.nodes.push([x, y, z]);
            }
        }
        self.set_nodes(tags, at)
    }

    /// 2.2 tag rule: the physical tag, else the elementary tag.
    pub(super) fn tag2(tags: &[i32]) -> i32 {
        match tags {
            [] => 0,
            [p, ..] if *p != 0 => *p,
            [_, e, ..] => *e,
            [_] => 0,
        }
    }

    pub(super) fn elements2_ascii(&mut self) -> Result<()> {
        let max = self.c.remaining() as u64;
        let n = self.c.count("number of elements", max)?;
        let mut raw = [0u64; 128];
        let mut tags = Vec::new();
        for _ in 0..n {
            let etag = self.c.u64("element tag")?;
            let ty = self.c.i32("element type")?;
            let k = self.element_type(ty)?;
            let ntags = self.c.count("number of tags", max)?;
            tags.clear();
            for _ in 0..ntags {
                tags.push(self.c.i32("element tag value")?);
            }
            if Self::kind_of(ty).is_some() {
                for r in raw.iter_mut().take(k) {
                    *r = self.c.u64("node tag")?;
                }
                self.eol()?;
                let tag = Self::tag2(&tags);
                self.push(ty, &raw[..k], etag, tag)?;
            } else {
                for _ in 0..k {
                    self.c.u64("node tag")?;
                }
                self.eol()?;
                self.mesh.ignored_elements += 1;
            }
        }
        Ok(())
    }

    pub(super) fn elements2_binary(&mut self) -> Result<()> {
        let n = self.c.u64("number of elements")?;
        self.c.rest_of_line();
        self.c.need(n, 12, "elements")?;
        let mut raw = [0u64; 128];
        let mut tags = Vec::new();
        let mut done = 0u64;
        while done < n {
            let ty = self.c.bin_i32("element type")?;
            let follow = self.c.bin_i32("number of elements following")?;
            let ntags = self.c.bin_i32("number of tags")?;
            let k = self.element_type(ty)?;
            if follow <= 0 || ntags < 0 || done + follow as u64 > n {
                return Err(self.c.err(format!(
                    "bad element block header: {follow} elements with {ntags} tags"
                )));
            }
            let (follow, ntags) = (follow as u64, ntags as usize);
            self.c.need(follow, 4 * (1 + ntags + k), "elements")?;
            if Self::kind_of(ty).is_none() {
                let size = follow as usize * 4 * (1 + ntags + k);
                self.c.bytes(size, "elements")?;
                self.mesh.ignored_elements += follow;
                done += follow;
                continue;
            }
            for _ in 0..follow {
                let etag = self.c.bin_i32("element tag")?;
                tags.clear();
                for _ in 0..ntags {
                    tags.push(self.c.bin_i32("element tag value")?);
                }
                for r in raw.iter_mut().take(k) {
                    // A negative tag is an unknown node: map it past every real tag.
                    *r = u64::try_from(self.c.bin_i32("node tag")?).unwrap_or(u64::MAX);
                }
                let tag = Self::tag2(&tags);
                self.push(ty, &raw[..k], etag as u64, tag)?;
            }
            done += follow;
        }
        Ok(())
    }
}
