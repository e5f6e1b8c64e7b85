//! Bodies with identical boxes merged in pairs before the split ([`Chunking::twins`], the fast
//! path).
//!
//! Identical boxes have the same Morton code, so the Morton order puts such bodies side by side
//! unless another body of the same code sits between them. Each pass over the order merges
//! every two neighbours with the same code and the same box (left to right, each body at most
//! once) into a body with that box in the first one's place; passes repeat while they merge, so
//! a run of k identical neighbours becomes one body in about log₂ k passes. A scene without
//! such neighbours costs one pass of code comparisons. With A ≥ 0 and C = 0 (the defaults) the
//! pair's Cost is at most either body's Cost with any other partner (Fill ½, the least, at the
//! least diameter), so merging them first is what the grouping step would choose; the split
//! then cuts a mesh of double-sided faces as one of half the size.
//!
//! [`Chunking::twins`]: super::Chunking::twins

use crate::geom::Aabb;

/// The merges of identical neighbours.
#[derive(Debug, Default)]
pub(super) struct Twins {
    /// Children of each merge, in merge order (new body `first + i`, `first` the length of the
    /// boxes before [`pair`]).
    pub(super) children: Vec<[u32; 2]>,
    /// Bodies the merges start from (not made by them).
    pub(super) bodies: u32,
}

/// Merges the identical neighbours of the Morton order `codes` (code, body id): each merge's
/// box and diameter are pushed onto `aabb` and `diameter` (ids follow on), and the pair's
/// entry in `codes` becomes one, with the new id, in the first one's place.
pub(super) fn pair(
    codes: &mut Vec<(u64, u32)>,
    aabb: &mut Vec<Aabb>,
    diameter: &mut Vec<f64>,
) -> Twins {
    let first = aabb.len();
    let mut children: Vec<[u32; 2]> = Vec::new();
    loop {
        let before = children.len();
        let len = codes.len();
        let (mut i, mut w) = (0, 0);
        while i < len {
            let (code, a) = codes[i];
            if i + 1 < len && codes[i + 1].0 == code {
                let b = codes[i + 1].1;
                if aabb[a as usize] == aabb[b as usize] {
                    let new = aabb.len() as u32;
                    aabb.push(aabb[a as usize]);
                    diameter.push(diameter[a as usize]);
                    children.push([a.min(b), a.max(b)]);
                    codes[w] = (code, new);
                    w += 1;
                    i += 2;
                    continue;
                }
            }
            codes[w] = codes[i];
            w += 1;
            i += 1;
        }
        codes.truncate(w);
        if children.len() == before {
            break;
        }
    }
    // Each merge takes two bodies and gives one; the roots are the new bodies left in `codes`.
    let roots = codes.iter().filter(|c| c.1 as usize >= first).count();
    Twins {
        bodies: (children.len() + roots) as u32,
        children,
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::geom::P3;

    fn cube(x: f64) -> Aabb {
        Aabb {
            min: P3::new(x, 0.0, 0.0),
            max: P3::new(x + 1.0, 1.0, 1.0),
        }
    }

    #[test]
    fn neighbours_with_the_same_box_merge_in_passes_and_others_stay() {
        // Bodies 0..6: 0 and 3 share a box, 1, 4 and 5 share another, 2 is alone, and 6 has
        // the code of 0 and 3 but another box.
        let mut aabb = vec![
            cube(0.0),
            cube(5.0),
            cube(9.0),
            cube(0.0),
            cube(5.0),
            cube(5.0),
            cube(0.5),
        ];
        let mut diameter: Vec<f64> = aabb.iter().map(Aabb::diameter).collect();
        let mut codes = vec![(1, 0), (1, 3), (1, 6), (2, 1), (2, 4), (2, 5), (3, 2)];
        let t = pair(&mut codes, &mut aabb, &mut diameter);
        // Pass 1: 0+3 → 7, 1+4 → 8; pass 2: 8+5 → 9; pass 3 merges nothing.
        assert_eq!(t.children, vec![[0, 3], [1, 4], [5, 8]]);
        assert_eq!(codes, vec![(1, 7), (1, 6), (2, 9), (3, 2)]);
        assert_eq!(t.bodies, 5);
        assert_eq!(aabb.len(), 10);
        assert_eq!(aabb[7], cube(0.0));
        assert_eq!(aabb[9], cube(5.0));
        assert_eq!(diameter[9], cube(5.0).diameter());
    }

    #[test]
    fn a_scene_of_one_box_becomes_one_body_and_distinct_boxes_change_nothing() {
        let mut aabb = vec![cube(1.0); 5];
        let mut diameter = vec![3f64.sqrt(); 5];
        let mut codes: Vec<(u64, u32)> = (0..5).map(|i| (7, i)).collect();
        let t = pair(&mut codes, &mut aabb, &mut diameter);
        assert_eq!(t.children.len(), 4);
        assert_eq!(t.bodies, 5);
        assert_eq!(codes.len(), 1);
        let mut aabb: Vec<Aabb> = (0..4).map(|i| cube(f64::from(i))).collect();
        let mut diameter = vec![1.0; 4];
        let mut codes: Vec<(u64, u32)> = (0..4).map(|i| (5, i)).collect();
        let t = pair(&mut codes, &mut aabb, &mut diameter);
        assert!(t.children.is_empty());
        assert_eq!(t.bodies, 0);
        assert_eq!(codes, (0..4).map(|i| (5, i)).collect::<Vec<_>>());
    }
}
