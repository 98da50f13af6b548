//! Gmsh .msh writer: 4.1 or 2.2, ASCII or binary (little-endian, `size_t` = 8 bytes).
//!
//! Layout (see `io` module docs): one surface entity per distinct boundary tag, in its own
//! physical group (the tag itself when positive, else a free number); one volume entity in
//! the volume's physical group (with several regions, one volume entity per region, its
//! tag and physical group the region id); `$PhysicalNames` for the named groups (see
//! [`Resolved`]). Node and element order are kept: node `i` has tag `i + 1`, and 4.1
//! element blocks follow runs of equal tags in the triangle list, so a file read back
//! gives the same indices.

use std::collections::BTreeMap;
use std::io::{self, Write};

use super::groups::Resolved;
use super::order::{self, Convention};
use super::text_out::{float, int, point, uint};
use super::{MeshView, MshVersion, WriteOptions};

const TRI6: i32 = 9;
const TET10: i32 = 11;
/// The volume's entity tag.
const VOLUME_ENTITY: i32 = 1;

/// For each volume entity of `volumes`, the surface entities of the triangles that are
/// faces of its tets (`tet_entity`), ascending.
fn bounding_surfaces(
    view: &MeshView,
    tri_entity: &[i32],
    volumes: &[(i32, i32)],
    tet_entity: &[i32],
) -> Vec<Vec<i32>> {
    let key = |mut f: [u32; 3]| {
        f.sort_unstable();
        f
    };
    let mut face_entity: std::collections::HashMap<[u32; 3], i32> =
        std::collections::HashMap::with_capacity(view.tri6.len());
    for (t, &e) in view.tri6.iter().zip(tri_entity) {
        face_entity.insert(key([t[0], t[1], t[2]]), e);
    }
    let mut per: BTreeMap<i32, std::collections::BTreeSet<i32>> = BTreeMap::new();
    for (t, &v) in view.tet10.iter().zip(tet_entity) {
        for f in [[0, 1, 2], [0, 1, 3], [0, 2, 3], [1, 2, 3]] {
            if let Some(&e) = face_entity.get(&key(f.map(|k| t[k]))) {
                per.entry(v).or_default().insert(e);
            }
        }
    }
    volumes
        .iter()
        .map(|(v, _)| {
            per.get(v)
                .map_or_else(Vec::new, |s| s.iter().copied().collect())
        })
        .collect()
}

/// Surface entities: one per boundary tag, each in its own physical group (see
/// [`Resolved`]); the entity's tag is its physical tag.
struct Entities {
    groups: Resolved,
    /// Each triangle's entity (= physical) tag.
    tri_entity: Vec<i32>,
    has_volume: bool,
    /// The volume entities as (entity tag, physical tag): one, or one per region.
    volumes: Vec<(i32, i32)>,
    /// Each tet's volume entity tag.
    tet_entity: Vec<i32>,
    /// With several regions, the surface entities bounding each volume entity (those
    /// with a triangle that is a face of one of its tets), ascending; empty otherwise
    /// (every surface entity bounds the one volume).
    volume_surfaces: Vec<Vec<i32>>,
}

impl Entities {
    fn new(view: &MeshView) -> Entities {
        let has_volume = !view.tet10.is_empty() || view.tri6.is_empty();
        let groups = Resolved::new(view.tags, view.groups, has_volume, view.tet_regions);
        let tri_entity = groups.triangle_tags(view.tags);
        // One region: entity VOLUME_ENTITY in the volume's group; several: each region
        // is its own entity and group, both numbered by its id.
        let (volumes, tet_entity) = if view.tet_regions.is_empty() {
            (
                vec![(VOLUME_ENTITY, groups.volume)],
                vec![VOLUME_ENTITY; view.tet10.len()],
            )
        } else {
            (
                groups.volumes.iter().map(|&r| (r, r)).collect(),
                view.tet_regions.to_vec(),
            )
        };
        let volume_surfaces = if view.tet_regions.is_empty() {
            Vec::new()
        } else {
            bounding_surfaces(view, &tri_entity, &volumes, &tet_entity)
        };
        Entities {
            groups,
            tri_entity,
            has_volume,
            volumes,
            tet_entity,
            volume_surfaces,
        }
    }

    /// The surface entities bounding volume entity number `i` (in `volumes`).
    fn bounding(&self, i: usize) -> Vec<i32> {
        match self.volume_surfaces.get(i) {
            Some(s) => s.clone(),
            None => self.surfaces(),
        }
    }

    /// The surface entity tags, ascending.
    fn surfaces(&self) -> Vec<i32> {
        let mut s: Vec<i32> = self.groups.surface.values().copied().collect();
        s.sort_unstable();
        s
    }

    /// Each node's entity (dim, tag): the first triangle using it, else (with several
    /// regions) the region of the first tet using it, else the (first) volume (or,
    /// without a volume, the first surface).
    fn node_entities(&self, view: &MeshView) -> Vec<(i32, i32)> {
        let fallback = if self.has_volume {
            (3, self.volumes[0].0)
        } else {
            (2, self.tri_entity[0])
        };
        let mut e = vec![(0, 0); view.nodes.len()];
        for (t, &ent) in view.tri6.iter().zip(&self.tri_entity) {
            for &v in t {
                if e[v as usize].0 == 0 {
                    e[v as usize] = (2, ent);
                }
            }
        }
        if !view.tet_regions.is_empty() {
            for (t, &ent) in view.tet10.iter().zip(&self.tet_entity) {
                for &v in t {
                    if e[v as usize].0 == 0 {
                        e[v as usize] = (3, ent);
                    }
                }
            }
        }
        for x in e.iter_mut() {
            if x.0 == 0 {
                *x = fallback;
            }
        }
        e
    }

    /// Bounding boxes of the surface entities and of the volume entities (by entity tag).
    fn bboxes(&self, view: &MeshView) -> (BTreeMap<i32, [f64; 6]>, BTreeMap<i32, [f64; 6]>) {
        const EMPTY: [f64; 6] = [
            f64::INFINITY,
            f64::INFINITY,
            f64::INFINITY,
            -f64::INFINITY,
            -f64::INFINITY,
            -f64::INFINITY,
        ];
        fn grow(b: &mut [f64; 6], p: &[f64; 3]) {
            for d in 0..3 {
                b[d] = b[d].min(p[d]);
                b[d + 3] = b[d + 3].max(p[d]);
            }
        }
        fn finish(b: &mut [f64; 6]) {
            if b[0] > b[3] {
                *b = [0.0; 6];
            }
        }
        let mut surf: BTreeMap<i32, [f64; 6]> = BTreeMap::new();
        for (t, &e) in view.tri6.iter().zip(&self.tri_entity) {
            let b = surf.entry(e).or_insert(EMPTY);
            for &v in t {
                grow(b, &view.nodes[v as usize]);
            }
        }
        surf.values_mut().for_each(finish);
        if !view.tet_regions.is_empty() {
            let mut vols: BTreeMap<i32, [f64; 6]> = BTreeMap::new();
            for (t, &e) in view.tet10.iter().zip(&self.tet_entity) {
                let b = vols.entry(e).or_insert(EMPTY);
                for &v in t {
                    grow(b, &view.nodes[v as usize]);
                }
            }
            vols.values_mut().for_each(finish);
            return (surf, vols);
        }
        // The nodes the tets use, marked and then swept in order: the same box as growing
        // it through the tets' nodes, without a random read of the node array for each.
        let mut used = vec![false; view.nodes.len()];
        for t in view.tet10 {
            for &v in t {
                used[v as usize] = true;
            }
        }
        let mut vol = EMPTY;
        for (p, _) in view.nodes.iter().zip(&used).filter(|(_, &u)| u) {
            grow(&mut vol, p);
        }
        finish(&mut vol);
        (surf, BTreeMap::from([(VOLUME_ENTITY, vol)]))
    }
}

/// Runs `[start, end)` of equal keys.
fn runs<T: PartialEq + Copy>(keys: &[T]) -> Vec<(usize, usize, T)> {
    let mut out = Vec::new();
    let mut s = 0;
    for i in 1..=keys.len() {
        if i == keys.len() || keys[i] != keys[s] {
            out.push((s, i, keys[s]));
            s = i;
        }
    }
    out
}

/// Write the mesh in the version and encoding `opts` asks for.
pub(crate) fn write<W: Write>(w: &mut W, view: &MeshView, opts: &WriteOptions) -> io::Result<()> {
    let mut o = Out {
        w,
        binary: opts.binary,
    };
    match opts.msh_version {
        MshVersion::V41 => write41(&mut o, view),
        MshVersion::V22 => write22(&mut o, view),
    }
}

/// A writer that puts values as text (space-separated) or as little-endian binary.
struct Out<'w, W: Write> {
    w: &'w mut W,
    binary: bool,
}

impl<W: Write> Out<'_, W> {
    fn raw(&mut self, s: &[u8]) -> io::Result<()> {
        self.w.write_all(s)
    }
    /// A `size_t` (8 bytes) in binary, a number followed by `sep` in text.
    fn size(&mut self, v: u64, sep: &[u8]) -> io::Result<()> {
        if self.binary {
            self.w.write_all(&v.to_le_bytes())
        } else {
            uint(self.w, v)?;
            self.w.write_all(sep)
        }
    }
    /// An `int` (4 bytes) in binary.
    fn int(&mut self, v: i32, sep: &[u8]) -> io::Result<()> {
        if self.binary {
            self.w.write_all(&v.to_le_bytes())
        } else {
            int(self.w, v as i64)?;
            self.w.write_all(sep)
        }
    }
    fn double(&mut self, v: f64, sep: &[u8]) -> io::Result<()> {
        if self.binary {
            self.w.write_all(&v.to_le_bytes())
        } else {
            float(self.w, v)?;
            self.w.write_all(sep)
        }
    }
    fn header(&mut self, version: &str) -> io::Result<()> {
        self.raw(b"$MeshFormat\n")?;
        self.raw(version.as_bytes())?;
        if self.binary {
            self.raw(b" 1 8\n")?;
            self.raw(&1i32.to_le_bytes())?;
            self.raw(b"\n")?;
        } else {
            self.raw(b" 0 8\n")?;
        }
        self.raw(b"$EndMeshFormat\n")
    }
    /// `$PhysicalNames` (text even in binary files), when there are names.
    fn names(&mut self, groups: &Resolved) -> io::Result<()> {
        if groups.names.is_empty() {
            return Ok(());
        }
        self.raw(b"$PhysicalNames\n")?;
        uint(self.w, groups.names.len() as u64)?;
        self.raw(b"\n")?;
        for n in &groups.names {
            uint(self.w, n.dim as u64)?;
            self.raw(b" ")?;
            int(self.w, n.tag as i64)?;
            self.raw(b" \"")?;
            self.raw(n.name.as_bytes())?;
            self.raw(b"\"\n")?;
        }
        self.raw(b"$EndPhysicalNames\n")
    }
    /// End a binary data run before the `$End...` line.
    fn end_data(&mut self) -> io::Result<()> {
        if self.binary {
            self.raw(b"\n")?;
        }
        Ok(())
    }
}

fn write41<W: Write>(o: &mut Out<W>, view: &MeshView) -> io::Result<()> {
    let ents = Entities::new(view);
    o.header("4.1")?;
    o.names(&ents.groups)?;

    // $Entities
    o.raw(b"$Entities\n")?;
    o.size(0, b" ")?;
    o.size(0, b" ")?;
    let surfaces = ents.surfaces();
    o.size(surfaces.len() as u64, b" ")?;
    let nvol = if ents.has_volume {
        ents.volumes.len()
    } else {
        0
    };
    o.size(nvol as u64, b"\n")?;
    let (surf_box, vol_box) = ents.bboxes(view);
    for &etag in &surfaces {
        let b = surf_box.get(&etag).copied().unwrap_or([0.0; 6]);
        o.int(etag, b" ")?;
        for x in b {
            o.double(x, b" ")?;
        }
        o.size(1, b" ")?;
        o.int(etag, b" ")?;
        o.size(0, b"\n")?;
    }
    for (i, &(etag, phys)) in ents.volumes[..nvol].iter().enumerate() {
        o.int(etag, b" ")?;
        for x in vol_box.get(&etag).copied().unwrap_or([0.0; 6]) {
            o.double(x, b" ")?;
        }
        o.size(1, b" ")?;
        o.int(phys, b" ")?;
        let bounding = ents.bounding(i);
        o.size(bounding.len() as u64, b"")?;
        for &etag in &bounding {
            if !o.binary {
                o.raw(b" ")?;
            }
            o.int(etag, b"")?;
        }
        if !o.binary {
            o.raw(b"\n")?;
        }
    }
    o.end_data()?;
    o.raw(b"$EndEntities\n")?;

    // $Nodes: one block per run of nodes on the same entity, in index order.
    let node_ent = ents.node_entities(view);
    let node_runs = runs(&node_ent);
    let n = view.nodes.len() as u64;
    o.raw(b"$Nodes\n")?;
    o.size(node_runs.len() as u64, b" ")?;
    o.size(n, b" ")?;
    o.size(n.min(1), b" ")?;
    o.size(n, b"\n")?;
    for &(s, e, (dim, etag)) in &node_runs {
        o.int(dim, b" ")?;
        o.int(etag, b" ")?;
        o.int(0, b" ")?;
        o.size((e - s) as u64, b"\n")?;
        for i in s..e {
            o.size(i as u64 + 1, b"\n")?;
        }
        for p in &view.nodes[s..e] {
            if o.binary {
                for x in p {
                    o.double(*x, b"")?;
                }
            } else {
                point(o.w, p)?;
                o.raw(b"\n")?;
            }
        }
    }
    o.end_data()?;
    o.raw(b"$EndNodes\n")?;

    // $Elements: triangle blocks per run of equal entity, then the tets.
    let tri_runs = runs(&ents.tri_entity);
    let tet_runs = runs(&ents.tet_entity);
    let nblocks = tri_runs.len() + tet_runs.len();
    let m = (view.tri6.len() + view.tet10.len()) as u64;
    o.raw(b"$Elements\n")?;
    o.size(nblocks as u64, b" ")?;
    o.size(m, b" ")?;
    o.size(m.min(1), b" ")?;
    o.size(m, b"\n")?;
    let mut tag = 1u64;
    for &(s, e, etag) in &tri_runs {
        o.int(2, b" ")?;
        o.int(etag, b" ")?;
        o.int(TRI6, b" ")?;
        o.size((e - s) as u64, b"\n")?;
        for t in &view.tri6[s..e] {
            o.size(tag, b" ")?;
            tag += 1;
            let t = order::tri6_to(Convention::Gmsh, t);
            for (k, &v) in t.iter().enumerate() {
                o.size(v as u64 + 1, if k == 5 { b"\n" } else { b" " })?;
            }
        }
    }
    for &(s, e, etag) in &tet_runs {
        o.int(3, b" ")?;
        o.int(etag, b" ")?;
        o.int(TET10, b" ")?;
        o.size((e - s) as u64, b"\n")?;
        for t in &view.tet10[s..e] {
            o.size(tag, b" ")?;
            tag += 1;
            let t = order::tet10_to(Convention::Gmsh, t);
            for (k, &v) in t.iter().enumerate() {
                o.size(v as u64 + 1, if k == 9 { b"\n" } else { b" " })?;
            }
        }
    }
    o.end_data()?;
    o.raw(b"$EndElements\n")
}

fn write22<W: Write>(o: &mut Out<W>, view: &MeshView) -> io::Result<()> {
    let ents = Entities::new(view);
    o.header("2.2")?;
    o.names(&ents.groups)?;

    let n = view.nodes.len();
    o.raw(b"$Nodes\n")?;
    uint(o.w, n as u64)?;
    o.raw(b"\n")?;
    for (i, p) in view.nodes.iter().enumerate() {
        o.int(i as i32 + 1, b" ")?;
        if o.binary {
            for x in p {
                o.double(*x, b"")?;
            }
        } else {
            point(o.w, p)?;
            o.raw(b"\n")?;
        }
    }
    o.end_data()?;
    o.raw(b"$EndNodes\n")?;

    let m = view.tri6.len() + view.tet10.len();
    o.raw(b"$Elements\n")?;
    uint(o.w, m as u64)?;
    o.raw(b"\n")?;
    let mut id = 1i32;
    if !view.tri6.is_empty() && o.binary {
        o.int(TRI6, b"")?;
        o.int(view.tri6.len() as i32, b"")?;
        o.int(2, b"")?;
    }
    for (t, &etag) in view.tri6.iter().zip(&ents.tri_entity) {
        o.int(id, b" ")?;
        id += 1;
        if !o.binary {
            o.raw(b"9 2 ")?;
        }
        o.int(etag, b" ")?;
        o.int(etag, b" ")?;
        let t = order::tri6_to(Convention::Gmsh, t);
        for (k, &v) in t.iter().enumerate() {
            o.int(v as i32 + 1, if k == 5 { b"\n" } else { b" " })?;
        }
    }
    if !view.tet10.is_empty() && o.binary {
        o.int(TET10, b"")?;
        o.int(view.tet10.len() as i32, b"")?;
        o.int(2, b"")?;
    }
    for (t, &etag) in view.tet10.iter().zip(&ents.tet_entity) {
        o.int(id, b" ")?;
        id += 1;
        if !o.binary {
            o.raw(b"11 2 ")?;
        }
        let phys = if view.tet_regions.is_empty() {
            ents.groups.volume
        } else {
            etag
        };
        o.int(phys, b" ")?;
        o.int(etag, b" ")?;
        let t = order::tet10_to(Convention::Gmsh, t);
        for (k, &v) in t.iter().enumerate() {
            o.int(v as i32 + 1, if k == 9 { b"\n" } else { b" " })?;
        }
    }
    o.end_data()?;
    o.raw(b"$EndElements\n")
}
