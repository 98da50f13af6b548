//! Gmsh .msh reader: versions 2.2 (2.0, 2.1) and 4.1, ASCII and binary.
//!
//! Hand-written: no maintained crate reads both versions in both encodings (mshio covers
//! 4.1 only), and we want exact error locations and hard caps on hostile header counts.
//! The whole file is in memory; numbers are parsed from the input slice with no
//! allocation per number.

use std::collections::HashMap;

use super::cursor::{capped, show, Cursor};
use super::msh_types::nodes_per_element;
use super::order::{self, Convention};
use super::{PhysicalName, RawMesh};
use crate::error::Result;

mod v2;
mod v41;

/// Element types curvetet keeps.
const TRI3: i32 = 2;
const TRI6: i32 = 9;
const TET4: i32 = 4;
const TET10: i32 = 11;

#[derive(Clone, Copy, PartialEq, Eq)]
enum Version {
    V2,
    V41,
}

/// Which list of the RawMesh a block of elements went to.
#[derive(Clone, Copy)]
enum Kind {
    Tri3,
    Tri6,
    Tet4,
    Tet10,
}

/// A run of elements from one (4.1) entity block whose tags are resolved at the end,
/// once `$Entities` has been seen.
struct Block {
    kind: Kind,
    start: usize,
    end: usize,
    dim: i32,
    entity: i32,
}

/// Node tags (arbitrary, possibly sparse) to 0-based indices.
enum NodeMap {
    Dense(Vec<u32>),
    Sparse(HashMap<u64, u32>),
}

impl NodeMap {
    /// Map sorted, distinct `tags` to their ranks 0, 1, 2...
    fn from_sorted(tags: &[u64]) -> NodeMap {
        let n = tags.len() as u64;
        let max = tags.last().copied().unwrap_or(0);
        if max <= 2 * n + 1024 {
            let mut v = vec![u32::MAX; max as usize + 1];
            for (i, &t) in tags.iter().enumerate() {
                v[t as usize] = i as u32;
            }
            NodeMap::Dense(v)
        } else {
            NodeMap::Sparse(
                tags.iter()
                    .enumerate()
                    .map(|(i, &t)| (t, i as u32))
                    .collect(),
            )
        }
    }

    #[inline]
    fn get(&self, tag: u64) -> Option<u32> {
        match self {
            NodeMap::Dense(v) => v.get(tag as usize).copied().filter(|&i| i != u32::MAX),
            NodeMap::Sparse(m) => m.get(&tag).copied(),
        }
    }
}

struct Reader<'a> {
    c: Cursor<'a>,
    version: Version,
    binary: bool,
    /// Gmsh's `size_t` in binary 4.1 files (4 or 8 bytes).
    dsize: usize,
    mesh: RawMesh,
    node_map: Option<NodeMap>,
    seen_elements: bool,
    blocks: Vec<Block>,
    /// (dim, entity tag) -> the entity's physical tag, for entities with exactly one.
    physical: HashMap<(i32, i32), i32>,
    /// The volume entities of `$Entities` (4.1).
    volumes: Vec<crate::io::VolumeEntity>,
}

/// Read a .msh file held in `data`; `name` is used in error locations.
pub(crate) fn read(data: &[u8], name: &str) -> Result<RawMesh> {
    let data = data.strip_prefix(b"\xEF\xBB\xBF").unwrap_or(data);
    let mut c = Cursor::new(data, name);
    let t = c.expect_token("$MeshFormat")?;
    if t != b"$MeshFormat" {
        return Err(c.err("not a Gmsh .msh file: expected '$MeshFormat'"));
    }
    let v = c.expect_token("format version")?;
    let version = match v {
        b"4.1" => Version::V41,
        b"2.2" | b"2" | b"2.0" | b"2.1" => Version::V2,
        b"4" | b"4.0" => {
            return Err(
                c.err("MSH 4.0 is not supported; convert it with 'gmsh FILE -0 -format msh41'")
            )
        }
        _ => {
            return Err(c.err(format!(
                "unsupported MSH version '{}' (supported: 2.2, 4.1)",
                show(v)
            )))
        }
    };
    let file_type = c.u64("file type")?;
    let dsize = c.u64("data size")?;
    if file_type > 1 {
        return Err(c.err(format!("file type must be 0 or 1, found {file_type}")));
    }
    let binary = file_type == 1;
    if binary {
        let ok = match version {
            Version::V41 => dsize == 4 || dsize == 8,
            Version::V2 => dsize == 8,
        };
        if !ok {
            return Err(c.err(format!("unsupported data size {dsize} in a binary file")));
        }
        c.set_binary(true);
        c.rest_of_line();
        let one = c.bytes(4, "the binary endianness check (int 1)")?;
        if one == 1i32.to_le_bytes() {
            c.set_swap(false);
        } else if one == 1i32.to_be_bytes() {
            c.set_swap(true);
        } else {
            return Err(c.err("bad endianness check: expected the int 1"));
        }
    }
    c.expect_word("$EndMeshFormat")?;

    let mut r = Reader {
        c,
        version,
        binary,
        dsize: dsize as usize,
        mesh: RawMesh::default(),
        node_map: None,
        seen_elements: false,
        blocks: Vec::new(),
        physical: HashMap::new(),
        volumes: Vec::new(),
    };
    r.sections()?;
    r.finish()
}

impl<'a> Reader<'a> {
    fn sections(&mut self) -> Result<()> {
        while let Some(tok) = self.c.token() {
            if self.binary
                && self.version == Version::V41
                && matches!(tok, b"$Nodes" | b"$Elements" | b"$Entities")
            {
                // Binary data starts on the line after the section name.
                self.c.rest_of_line();
            }
            match tok {
                b"$Nodes" => {
                    if self.node_map.is_some() {
                        return Err(self.c.err("a second $Nodes section is not supported"));
                    }
                    match (self.version, self.binary) {
                        (Version::V41, false) => self.nodes41_ascii()?,
                        (Version::V41, true) => self.nodes41_binary()?,
                        (Version::V2, _) => self.nodes2()?,
                    }
                    self.c.expect_word("$EndNodes")?;
                }
                b"$Elements" => {
                    if self.node_map.is_none() {
                        return Err(self.c.err("$Elements before $Nodes"));
                    }
                    if self.seen_elements {
                        return Err(self.c.err("a second $Elements section is not supported"));
                    }
                    self.seen_elements = true;
                    match (self.version, self.binary) {
                        (Version::V41, false) => self.elements41_ascii()?,
                        (Version::V41, true) => self.elements41_binary()?,
                        (Version::V2, false) => self.elements2_ascii()?,
                        (Version::V2, true) => self.elements2_binary()?,
                    }
                    self.c.expect_word("$EndElements")?;
                }
                b"$PhysicalNames" => {
                    self.physical_names()?;
                    self.c.expect_word("$EndPhysicalNames")?;
                }
                b"$Entities" if self.version == Version::V41 => {
                    if self.binary {
                        self.entities_binary()?
                    } else {
                        self.entities_ascii()?
                    }
                    self.c.expect_word("$EndEntities")?;
                }
                t if t.len() > 1 && t[0] == b'$' && !t.starts_with(b"$End") => {
                    self.skip_section(&t[1..])?
                }
                t => {
                    return Err(self.c.err(format!(
                        "expected a section such as $Nodes, found '{}'",
                        show(t)
                    )))
                }
            }
        }
        Ok(())
    }

    /// `$PhysicalNames` (text in binary files too): a count, then `dim tag "name"` lines.
    fn physical_names(&mut self) -> Result<()> {
        // Each line takes at least 7 bytes (`2 1 ""` and its line break).
        let max = (self.c.remaining() / 7) as u64;
        let n = self.c.count("number of physical names", max)?;
        for _ in 0..n {
            let dim = self.c.i32("physical name dimension")?;
            if !(0..=3).contains(&dim) {
                return Err(self
                    .c
                    .err(format!("physical name dimension {dim} is not 0, 1, 2 or 3")));
            }
            let tag = self.c.i32("physical tag")?;
            let line = self.c.rest_of_line();
            let t = line.trim_ascii();
            let name = match t {
                [b'"', inner @ .., b'"'] => inner,
                _ => {
                    return Err(self.c.err(format!(
                        "physical group {tag}: expected its name in double quotes, found '{}'",
                        show(t)
                    )))
                }
            };
            self.mesh.physical_names.push(PhysicalName {
                dim: dim as u8,
                tag,
                name: String::from_utf8_lossy(name).into_owned(),
            });
        }
        Ok(())
    }

    /// Skip an unknown section to its `$End` line.
    fn skip_section(&mut self, name: &[u8]) -> Result<()> {
        let start = self.c.pos();
        let mut pat = b"$End".to_vec();
        pat.extend_from_slice(name);
        let rest = &self.c.data()[start..];
        match rest.windows(pat.len()).position(|w| w == pat.as_slice()) {
            Some(k) => {
                self.c.seek(start + k + pat.len());
                Ok(())
            }
            None => Err(self.c.err(format!(
                "section ${} has no matching $End{}",
                show(name),
                show(name)
            ))),
        }
    }

    fn finish(mut self) -> Result<RawMesh> {
        if self.node_map.is_none() {
            return Err(self.c.eof("a $Nodes section"));
        }
        if !self.seen_elements {
            return Err(self.c.eof("an $Elements section"));
        }
        // Entity tags become physical tags where the entity has exactly one.
        for b in &self.blocks {
            let tag = self
                .physical
                .get(&(b.dim, b.entity))
                .copied()
                .unwrap_or(b.entity);
            let tags = match b.kind {
                Kind::Tri3 => &mut self.mesh.tri3_tags,
                Kind::Tri6 => &mut self.mesh.tri6_tags,
                Kind::Tet4 => &mut self.mesh.tet4_tags,
                Kind::Tet10 => &mut self.mesh.tet10_tags,
            };
            tags[b.start..b.end].fill(tag);
        }
        // A surface file whose entities list volumes: which surface entity each triangle
        // is on, for the regions (a file with tetrahedra is a mesh already).
        let m = &mut self.mesh;
        if !self.volumes.is_empty() && m.tet4.is_empty() && m.tet10.is_empty() {
            m.tri3_entities = vec![0; m.tri3.len()];
            m.tri6_entities = vec![0; m.tri6.len()];
            for b in &self.blocks {
                match b.kind {
                    Kind::Tri3 => m.tri3_entities[b.start..b.end].fill(b.entity),
                    Kind::Tri6 => m.tri6_entities[b.start..b.end].fill(b.entity),
                    _ => {}
                }
            }
            m.volumes = std::mem::take(&mut self.volumes);
        }
        Ok(self.mesh)
    }

    // ----- $Nodes -----

    /// Number the nodes by ascending tag (node tag `t` of a file tagged 1..N becomes
    /// index `t - 1`), whatever order the blocks list them in.
    fn set_nodes(&mut self, mut tags: Vec<u64>, at: usize) -> Result<()> {
        if !tags.windows(2).all(|w| w[0] < w[1]) {
            let mut order: Vec<u32> = (0..tags.len() as u32).collect();
            order.sort_unstable_by_key(|&i| tags[i as usize]);
            let nodes = &self.mesh.nodes;
            self.mesh.nodes = order.iter().map(|&i| nodes[i as usize]).collect();
            tags = order.iter().map(|&i| tags[i as usize]).collect();
            if let Some(w) = tags.windows(2).find(|w| w[0] == w[1]) {
                return Err(self
                    .c
                    .err_at(at, format!("node tag {} is defined twice", w[0])));
            }
        }
        self.node_map = Some(NodeMap::from_sorted(&tags));
        Ok(())
    }

    // ----- $Elements -----

    /// Map node tags to indices for element `etag`.
    #[inline]
    fn map<const K: usize>(&self, raw: &[u64; K], etag: u64) -> Result<[u32; K]> {
        let map = self.node_map.as_ref().expect("nodes read before elements");
        let mut out = [0u32; K];
        for (o, &t) in out.iter_mut().zip(raw) {
            *o = map.get(t).ok_or_else(|| {
                self.c.err(format!(
                    "element {etag} refers to node {t}, which does not exist"
                ))
            })?;
        }
        Ok(out)
    }

    /// Store one element of a kept type with (provisional) tag `tag`.
    #[inline]
    fn push(&mut self, ty: i32, raw: &[u64], etag: u64, tag: i32) -> Result<()> {
        match ty {
            TRI3 => {
                let v = self.map::<3>(raw.try_into().expect("3 nodes"), etag)?;
                self.mesh.tri3.push(v);
                self.mesh.tri3_tags.push(tag);
            }
            TRI6 => {
                let v = self.map::<6>(raw.try_into().expect("6 nodes"), etag)?;
                self.mesh.tri6.push(order::tri6_from(Convention::Gmsh, &v));
                self.mesh.tri6_tags.push(tag);
            }
            TET4 => {
                let v = self.map::<4>(raw.try_into().expect("4 nodes"), etag)?;
                self.mesh.tet4.push(v);
                self.mesh.tet4_tags.push(tag);
            }
            TET10 => {
                let v = self.map::<10>(raw.try_into().expect("10 nodes"), etag)?;
                self.mesh
                    .tet10
                    .push(order::tet10_from(Convention::Gmsh, &v));
                self.mesh.tet10_tags.push(tag);
            }
            _ => self.mesh.ignored_elements += 1,
        }
        Ok(())
    }

    fn kind_len(&self, kind: Kind) -> usize {
        match kind {
            Kind::Tri3 => self.mesh.tri3.len(),
            Kind::Tri6 => self.mesh.tri6.len(),
            Kind::Tet4 => self.mesh.tet4.len(),
            Kind::Tet10 => self.mesh.tet10.len(),
        }
    }

    fn kind_of(ty: i32) -> Option<Kind> {
        match ty {
            TRI3 => Some(Kind::Tri3),
            TRI6 => Some(Kind::Tri6),
            TET4 => Some(Kind::Tet4),
            TET10 => Some(Kind::Tet10),
            _ => None,
        }
    }

    fn reserve(&mut self, kind: Kind, n: usize) {
        match kind {
            Kind::Tri3 => (self.mesh.tri3.reserve(n), self.mesh.tri3_tags.reserve(n)),
            Kind::Tri6 => (self.mesh.tri6.reserve(n), self.mesh.tri6_tags.reserve(n)),
            Kind::Tet4 => (self.mesh.tet4.reserve(n), self.mesh.tet4_tags.reserve(n)),
            Kind::Tet10 => (self.mesh.tet10.reserve(n), self.mesh.tet10_tags.reserve(n)),
        };
    }

    fn element_type(&self, ty: i32) -> Result<usize> {
        nodes_per_element(ty).ok_or_else(|| self.c.err(format!("unknown element type {ty}")))
    }

    /// In ASCII, an element ends its line: anything else means a miscounted element.
    fn eol(&mut self) -> Result<()> {
        let d = self.c.data();
        let mut p = self.c.pos();
        while p < d.len() && (d[p] == b' ' || d[p] == b'\t' || d[p] == b'\r') {
            p += 1;
        }
        if p < d.len() && d[p] != b'\n' {
            return Err(self
                .c
                .err_at(p, "unexpected extra data after the element's nodes"));
        }
        self.c.seek(p);
        Ok(())
    }
}
