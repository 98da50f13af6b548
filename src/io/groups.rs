//! Physical groups: the numbers and names under which the writers put each boundary part
//! and the volume, so a solver can apply boundary conditions by name.
//!
//! A mesh's triangle tags say which boundary part each triangle is on; [`Groups`] adds the
//! volume's number and the names the input gave (Gmsh `$PhysicalNames`). The writers turn
//! both into a [`Resolved`] set where every boundary part and the volume is a group with a
//! positive number: Gmsh needs positive physical tags, and meshio refuses a file where
//! some entities have a physical group and others have none. Untagged triangles (tag 0,
//! as every STL/OFF/OBJ/PLY input has) become group 1 named `boundary` (or the first free
//! number), and the volume is named `volume` unless the input named it.

use std::collections::{BTreeMap, BTreeSet};

use super::VOLUME_TAG;

/// The name of the group holding untagged (tag 0) boundary triangles.
pub const UNTAGGED_BOUNDARY_NAME: &str = "boundary";
/// The name of the volume group when the input does not name it.
pub const DEFAULT_VOLUME_NAME: &str = "volume";
/// Unnamed regions of a mesh of several regions are named this followed by their id.
pub const REGION_NAME_PREFIX: &str = "region_";

/// A named physical group, as in Gmsh's `$PhysicalNames`: dimension (2 surface, 3 volume),
/// tag, name.
#[derive(Debug, Clone, PartialEq, Eq, PartialOrd, Ord, Hash, serde::Serialize)]
pub struct PhysicalName {
    /// 0 point, 1 curve, 2 surface, 3 volume.
    pub dim: u8,
    /// The group's (positive) tag.
    pub tag: i32,
    /// Its name.
    pub name: String,
}

/// What a mesh carries besides its triangle tags: the volume's tag and the group names.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct Groups {
    /// The physical tag of the tetrahedra (default [`VOLUME_TAG`]); a value <= 0 is
    /// written as [`VOLUME_TAG`].
    pub volume_tag: i32,
    /// Names of physical groups (any dimension; the writers keep those of the groups they
    /// write).
    pub names: Vec<PhysicalName>,
}

impl Default for Groups {
    fn default() -> Self {
        Groups {
            volume_tag: VOLUME_TAG,
            names: Vec::new(),
        }
    }
}

impl Groups {
    /// The name of group (`dim`, `tag`), if the input named it.
    pub fn name(&self, dim: u8, tag: i32) -> Option<&str> {
        self.names
            .iter()
            .find(|n| n.dim == dim && n.tag == tag)
            .map(|n| n.name.as_str())
    }
}

/// The groups a writer puts in a file.
pub(crate) struct Resolved {
    /// Triangle tag -> its physical tag (positive).
    pub surface: BTreeMap<i32, i32>,
    /// The volume's physical tag (positive).
    pub volume: i32,
    /// The volume groups written: `[volume]`, or the region ids of a mesh of several
    /// regions (ascending).
    pub volumes: Vec<i32>,
    /// Names of the groups written, sorted by (dim, tag).
    pub names: Vec<PhysicalName>,
}

impl Resolved {
    /// The groups of a mesh with triangle tags `tags`, with a volume if `has_volume`,
    /// and region ids `regions` per tet (empty: one volume).
    pub fn new(tags: &[i32], groups: &Groups, has_volume: bool, regions: &[i32]) -> Resolved {
        let distinct: BTreeSet<i32> = tags.iter().copied().collect();
        let mut surface = BTreeMap::new();
        let mut used: BTreeSet<i32> = distinct.iter().copied().filter(|&t| t > 0).collect();
        for &t in &used {
            surface.insert(t, t);
        }
        // Non-positive tags, 0 first, then -1, -2, ...: the first free positive numbers.
        let mut fresh = 1;
        for &t in distinct.iter().rev().filter(|&&t| t <= 0) {
            while used.contains(&fresh) {
                fresh += 1;
            }
            used.insert(fresh);
            surface.insert(t, fresh);
        }
        let volume = if groups.volume_tag > 0 {
            groups.volume_tag
        } else {
            VOLUME_TAG
        };
        let mut names = BTreeSet::new();
        let mut taken: BTreeSet<&str> = BTreeSet::new();
        for (&t, &p) in &surface {
            if t > 0 {
                if let Some(n) = groups.name(2, t) {
                    names.insert(PhysicalName {
                        dim: 2,
                        tag: p,
                        name: clean(n),
                    });
                    taken.insert(n);
                }
            }
        }
        if let Some(&p) = surface.get(&0) {
            if !taken.contains(UNTAGGED_BOUNDARY_NAME) {
                names.insert(PhysicalName {
                    dim: 2,
                    tag: p,
                    name: UNTAGGED_BOUNDARY_NAME.to_string(),
                });
            }
        }
        let mut volumes: Vec<i32> = regions.to_vec();
        volumes.sort_unstable();
        volumes.dedup();
        if volumes.is_empty() {
            volumes.push(volume);
            if has_volume {
                names.insert(PhysicalName {
                    dim: 3,
                    tag: volume,
                    name: clean(groups.name(3, volume).unwrap_or(DEFAULT_VOLUME_NAME)),
                });
            }
        } else {
            for &r in &volumes {
                let name = groups
                    .name(3, r)
                    .map(clean)
                    .unwrap_or_else(|| format!("{REGION_NAME_PREFIX}{r}"));
                names.insert(PhysicalName {
                    dim: 3,
                    tag: r,
                    name,
                });
            }
        }
        Resolved {
            surface,
            volume: volumes[0],
            volumes,
            names: names.into_iter().collect(),
        }
    }

    /// The physical tag of each triangle.
    pub fn triangle_tags(&self, tags: &[i32]) -> Vec<i32> {
        tags.iter().map(|t| self.surface[t]).collect()
    }
}

/// A name as a Gmsh file can hold it: one line, no double quote.
fn clean(name: &str) -> String {
    name.chars()
        .map(|c| match c {
            '"' => '\'',
            c if c.is_control() => ' ',
            c => c,
        })
        .collect()
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The resolved groups' names as (dim, tag, name).
    fn names_of(r: &Resolved) -> Vec<(u8, i32, &str)> {
        r.names
            .iter()
            .map(|n| (n.dim, n.tag, n.name.as_str()))
            .collect()
    }

    #[test]
    fn regions_are_volume_groups_named_by_the_input_or_by_id() {
        let g = Groups {
            volume_tag: 1,
            names: vec![PhysicalName {
                dim: 3,
                tag: 7,
                name: "blood".into(),
            }],
        };
        let r = Resolved::new(&[0, 0], &g, true, &[7, 2, 7]);
        assert_eq!(r.volumes, vec![2, 7]);
        assert_eq!(r.volume, 2);
        let names = names_of(&r);
        assert_eq!(
            names,
            vec![(2, 1, "boundary"), (3, 2, "region_2"), (3, 7, "blood")]
        );
    }

    #[test]
    fn untagged_becomes_boundary_one_and_volume_is_named() {
        let r = Resolved::new(&[0, 0, 0], &Groups::default(), true, &[]);
        assert_eq!(r.surface[&0], 1);
        assert_eq!(r.volume, VOLUME_TAG);
        let names = names_of(&r);
        assert_eq!(names, vec![(2, 1, "boundary"), (3, 1, "volume")]);
    }

    #[test]
    fn input_numbers_and_names_are_kept_and_non_positive_tags_take_free_numbers() {
        let g = Groups {
            volume_tag: 4,
            names: vec![
                PhysicalName {
                    dim: 2,
                    tag: 1,
                    name: "inlet".into(),
                },
                PhysicalName {
                    dim: 3,
                    tag: 4,
                    name: "fluid \"x\"".into(),
                },
            ],
        };
        let r = Resolved::new(&[1, 3, 0, -2, 3], &g, true, &[]);
        assert_eq!(r.triangle_tags(&[1, 3, 0, -2]), vec![1, 3, 2, 4]);
        assert_eq!(r.volume, 4);
        let names = names_of(&r);
        assert_eq!(
            names,
            vec![(2, 1, "inlet"), (2, 2, "boundary"), (3, 4, "fluid 'x'")]
        );
    }
}
