//! The closest-piece search of the meshed surfaces ([`crate::triangles`], [`crate::polyline`])
//! in an R*-tree of their pieces' bounding boxes: every piece as near to a point as the nearest
//! one up to round-off, so that ties between pieces resolve by a rule of the surface, not by
//! the tree.

use rstar::{AABB, ParentNode, RTree, RTreeNode, RTreeObject};

/// The pieces of `tree` in the chain of ties from the nearest to `point`, each as `measure`
/// gives it (its result and its exact distance, never below the distance of its bounding box):
/// with the pieces' distances sorted, those up to the first gap wider than `2 tolerance`.
/// Empty for an empty tree or where no distance is a number.
///
/// A greedy descent to the leaf of the nearest boxes bounds the nearest distance from above;
/// the pieces within that bound and `2 tolerance` are collected by a walk that skips every box
/// farther than that, and the bound widens while the chain reaches it. Every piece left out is
/// more than `2 tolerance` farther than every piece kept.
pub(crate) fn nearest_chain<const N: usize, T, R>(
    tree: &RTree<T>,
    point: [f64; N],
    tolerance: f64,
    measure: impl Fn(&T) -> (R, f64),
) -> Vec<R>
where
    T: RTreeObject<Envelope = AABB<[f64; N]>>,
    [f64; N]: rstar::Point<Scalar = f64>,
{
    let box_distance = |node: &RTreeNode<T>| node.envelope().distance_2(&point);
    let mut node = tree.root();
    let bound = loop {
        let Some((_, nearest)) = (node.children().iter())
            .map(|child| (box_distance(child), child))
            .min_by(|a, b| a.0.total_cmp(&b.0))
        else {
            return Vec::new();
        };
        match nearest {
            RTreeNode::Parent(parent) => node = parent,
            RTreeNode::Leaf(piece) => break measure(piece).1,
        }
    };
    let mut reach = bound + 2.0 * tolerance;
    let mut found = Vec::new();
    loop {
        found.clear();
        collect_within(tree.root(), &point, reach, &measure, &mut found);
        found.sort_unstable_by(|a, b| a.1.total_cmp(&b.1));
        let chain = 1
            + (found.windows(2))
                .take_while(|pair| pair[1].1 <= pair[0].1 + 2.0 * tolerance)
                .count();
        let Some(&(_, last)) = found.get(chain - 1) else {
            return Vec::new();
        };
        if chain < found.len() || last + 2.0 * tolerance <= reach {
            found.truncate(chain);
            return found.into_iter().map(|(result, _)| result).collect();
        }
        reach = last + 2.0 * tolerance;
    }
}

/// Every piece under `node` within `reach` of `point` (its box first, then its measured
/// distance), as `measure` gives it, into `out`.
fn collect_within<const N: usize, T, R>(
    node: &ParentNode<T>,
    point: &[f64; N],
    reach: f64,
    measure: &impl Fn(&T) -> (R, f64),
    out: &mut Vec<(R, f64)>,
) where
    T: RTreeObject<Envelope = AABB<[f64; N]>>,
    [f64; N]: rstar::Point<Scalar = f64>,
{
    let squared = reach * reach;
    for child in node.children() {
        if child.envelope().distance_2(point) > squared {
            continue;
        }
        match child {
            RTreeNode::Parent(parent) => collect_within(parent, point, reach, measure, out),
            RTreeNode::Leaf(piece) => {
                let (result, distance) = measure(piece);
                if distance <= reach {
                    out.push((result, distance));
                }
            }
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Points on a line, searched from the origin: the chain of ties from the nearest,
    /// whatever the tree's order, and nothing past its first wide gap; a tree of many points
    /// gives the chain a scan of all of them gives.
    #[test]
    fn the_chain_of_ties_from_the_nearest() {
        let tree = RTree::bulk_load(vec![
            [1.0, 0.0],
            [1.15, 0.0],
            [1.3, 0.0],
            [1.6, 0.0],
            [2.0, 0.0],
        ]);
        let distance = |p: &[f64; 2]| (p[0], p[0].hypot(p[1]));
        let mut chain = nearest_chain(&tree, [0.0, 0.0], 0.1, distance);
        chain.sort_by(f64::total_cmp);
        assert_eq!(chain, vec![1.0, 1.15, 1.3]);
        assert_eq!(nearest_chain(&tree, [0.0, 0.0], 0.0, distance), vec![1.0]);
        let empty: RTree<[f64; 2]> = RTree::new();
        assert!(nearest_chain(&empty, [0.0, 0.0], 0.1, distance).is_empty());

        // a grid of 400 points, from points among them and between them
        let points: Vec<[f64; 2]> = (0..400)
            .map(|k| [f64::from(k % 20) * 0.1, f64::from(k / 20) * 0.1])
            .collect();
        let tree = RTree::bulk_load(points.clone());
        for query in [[0.55, 0.55], [1.0, 1.0], [-0.3, 0.72], [2.5, 0.05]] {
            let measure = |p: &[f64; 2]| (*p, (p[0] - query[0]).hypot(p[1] - query[1]));
            let mut found = nearest_chain(&tree, query, 1e-9, measure);
            let nearest = points
                .iter()
                .map(|p| measure(p).1)
                .fold(f64::INFINITY, f64::min);
            let mut expected: Vec<[f64; 2]> = (points.iter())
                .filter(|p| measure(p).1 <= nearest + 2e-9)
                .copied()
                .collect();
            let order =
                |a: &[f64; 2], b: &[f64; 2]| a[0].total_cmp(&b[0]).then(a[1].total_cmp(&b[1]));
            found.sort_by(order);
            expected.sort_by(order);
            assert_eq!(found, expected, "from {query:?}");
        }
    }
}
