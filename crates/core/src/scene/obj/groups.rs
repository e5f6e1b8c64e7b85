//! `tobj`'s models as groups of faces over the scene's points, the coordinates taken from the
//! pre-pass ([`scan`](super::scan)).

use std::hash::BuildHasher;

use crate::geom::P3;
use crate::scene::LoadErrorKind;
use crate::stop::Stop;

/// One OBJ object/group: its name and its faces as indices into the scene's points.
pub(super) struct Group {
    pub(super) name: String,
    /// All faces' vertex indices, concatenated.
    verts: Vec<u32>,
    /// Offsets into `verts`, one more than the faces.
    starts: Vec<usize>,
}

impl Group {
    /// The faces, in file order.
    pub(super) fn faces(&self) -> impl Iterator<Item = &[u32]> {
        self.starts.windows(2).map(|w| &self.verts[w[0]..w[1]])
    }
}

/// Splits a vertex index into two parts that `f32` holds exactly (`tobj` parses `f32`).
pub(super) const INDEX_SPLIT: u64 = 1 << 20;

/// Moves `tobj`'s models into `points` (merging bit-identical positions) and returns the groups.
///
/// `coords` are the file's vertices as parsed by [`scan`](super::scan); `tobj`'s positions
/// only carry the vertex indices (see [`scan`](super::scan)). `stop` is checked every
/// [`STRIDE`](crate::stop::STRIDE) positions (Err: [`LoadErrorKind::Interrupted`]).
pub(super) fn collect_groups(
    models: &[tobj::Model],
    coords: &[[f64; 3]],
    points: &mut Vec<P3>,
    stop: &Stop,
) -> Result<Vec<Group>, (LoadErrorKind, String)> {
    let malformed = |what: &str| {
        (
            LoadErrorKind::Malformed,
            format!("not a valid OBJ file ({what})"),
        )
    };
    // The distinct coordinates as a table of point ids (4 bytes a slot, not a key's 28: at 3×10^6
    // vertices the table stays in 16 MB), compared through `points`.
    let hasher = foldhash::fast::FixedState::with_seed(0);
    let hash = |k: &[u64; 3]| hasher.hash_one(k);
    let bits = |p: &P3| [p.x.to_bits(), p.y.to_bits(), p.z.to_bits()];
    let mut ids = hashbrown::HashTable::<u32>::with_capacity(coords.len());
    // At most one point per vertex line.
    points.reserve(coords.len());
    let mut of_file = vec![u32::MAX; coords.len()];
    let mut groups = Vec::with_capacity(models.len());
    for model in models {
        let mesh = &model.mesh;
        let mut local = Vec::with_capacity(mesh.positions.len() / 3);
        for (k, c) in mesh.positions.chunks_exact(3).enumerate() {
            stop.check_every(k)
                .map_err(|e| (LoadErrorKind::Interrupted, e.to_string()))?;
            let file = (f64::from(c[1]) as u64 * INDEX_SPLIT + f64::from(c[0]) as u64) as usize;
            let slot = of_file
                .get_mut(file)
                .ok_or_else(|| malformed("vertex index"))?;
            if *slot == u32::MAX {
                // `+ 0.0` turns -0.0 into 0.0 so both spellings merge.
                let p = coords[file].map(|x| x + 0.0);
                let key = p.map(f64::to_bits);
                let found = |&id: &u32| bits(&points[id as usize]) == key;
                *slot = match ids.find(hash(&key), found) {
                    Some(&id) => id,
                    None => {
                        let id = points.len() as u32;
                        points.push(P3::from(p));
                        ids.insert_unique(hash(&key), id, |&i| hash(&bits(&points[i as usize])));
                        id
                    }
                };
            }
            local.push(*slot);
        }
        let arities: Box<dyn Iterator<Item = usize>> = if mesh.face_arities.is_empty() {
            Box::new(std::iter::repeat_n(3, mesh.indices.len() / 3))
        } else {
            Box::new(mesh.face_arities.iter().map(|&a| a as usize))
        };
        let mut g = Group {
            name: model.name.clone(),
            verts: Vec::with_capacity(mesh.indices.len()),
            starts: vec![0],
        };
        let mut at = 0usize;
        for n in arities {
            let idx = mesh
                .indices
                .get(at..at + n)
                .ok_or_else(|| malformed("face list"))?;
            at += n;
            if n >= 3 {
                for &i in idx {
                    g.verts.push(
                        *local
                            .get(i as usize)
                            .ok_or_else(|| malformed("face index"))?,
                    );
                }
                g.starts.push(g.verts.len());
            }
        }
        if g.starts.len() > 1 {
            groups.push(g);
        }
    }
    Ok(groups)
}

#[cfg(test)]
mod tests {
    use super::super::{LoadOptions, load};
    use crate::geom::P3;

    #[test]
    fn bit_identical_positions_become_one_point_in_order_of_first_use() {
        // Vertex 4 repeats 2 (with −0), 5 repeats 3, 6 is unused; the first face uses 4, 5, 7.
        let obj = "v 0 0 0\nv 1 0 0\nv 0 1 0\nv 1 0 -0\nv 0 1 0\nv 5 5 5\nv 0 0 1\n\
                   o a\nf 4 5 7\no b\nf 1 2 3\n";
        let l = load(
            "dup.obj",
            obj.as_bytes().to_vec(),
            &LoadOptions::default(),
            &crate::stop::Stop::new(),
        )
        .unwrap();
        let want = [
            [1.0, 0.0, 0.0],
            [0.0, 1.0, 0.0],
            [0.0, 0.0, 1.0],
            [0.0, 0.0, 0.0],
        ];
        let want: Vec<P3> = want.iter().map(|&c| P3::from(c)).collect();
        assert_eq!(l.scene.points, want);
        assert!(
            l.scene
                .points
                .iter()
                .all(|p| p.x.to_bits() != (-0.0f64).to_bits())
        );
        assert_eq!(l.scene.prim(0), [0, 1, 2]);
        assert_eq!(l.scene.prim(1), [3, 0, 1]);
        assert_eq!(l.scene.objects, [0, 1]);
    }
}
