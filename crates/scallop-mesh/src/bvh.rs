//! A 3D bounding-volume hierarchy over boxes (triangles of a mesh, segments of
//! polylines): median splits along the longest axis, leaves of a few items.
//! Queries are branch-and-bound and deterministic: ties go to the lower item
//! number whatever the visiting order.

use scallop_geom::{Aabb3, Point3, Vec3};

const LEAF_SIZE: usize = 4;

#[derive(Clone, Copy, Debug)]
struct Node {
    min: [f64; 3],
    max: [f64; 3],
    /// Leaf: first slot. Inner: index of the second child (the first is `self + 1`).
    first_or_right: u32,
    /// Leaf: number of slots (> 0). Inner: 0.
    count: u32,
}

impl Node {
    fn distance_squared(&self, p: &Point3) -> f64 {
        let mut d2 = 0.0;
        for k in 0..3 {
            let v = p[k];
            let d = if v < self.min[k] {
                self.min[k] - v
            } else if v > self.max[k] {
                v - self.max[k]
            } else {
                0.0
            };
            d2 += d * d;
        }
        d2
    }

    fn overlaps(&self, b: &Aabb3) -> bool {
        (0..3).all(|k| self.min[k] <= b.max[k] && b.min[k] <= self.max[k])
    }

    /// Parameter interval of the line `origin + t dir` inside the box, if any
    /// part of `[t0, t1]` is.
    fn slab(&self, origin: &Point3, inv: &Vec3, t0: f64, t1: f64) -> Option<f64> {
        let (mut lo, mut hi) = (t0, t1);
        for k in 0..3 {
            let a = (self.min[k] - origin[k]) * inv[k];
            let b = (self.max[k] - origin[k]) * inv[k];
            let (a, b) = if a <= b { (a, b) } else { (b, a) };
            // NaN (0 * inf on a box face) keeps the interval: conservative.
            if a > lo {
                lo = a;
            }
            if b < hi {
                hi = b;
            }
        }
        (lo <= hi).then_some(lo)
    }
}

/// A hierarchy over items given by their boxes; items keep their numbers.
#[derive(Debug, Clone)]
pub struct Bvh {
    nodes: Vec<Node>,
    /// Item numbers in leaf order.
    order: Vec<u32>,
}

impl Bvh {
    /// Builds the hierarchy over `boxes` (item `i` has box `boxes[i]`).
    ///
    /// ```
    /// use scallop_geom::{Aabb3, Point3};
    /// let xs = [0.0, 5.0, 10.0];
    /// let boxes: Vec<Aabb3> = xs.iter().map(|&x| Aabb3 { min: Point3::new(x, 0., 0.), max: Point3::new(x, 0., 0.) }).collect();
    /// let bvh = scallop_mesh::Bvh::build(&boxes);
    /// let p = Point3::new(6.0, 0.0, 0.0);
    /// let (item, d2) = bvh.nearest(&p, f64::INFINITY, |i| (xs[i] - 6.0_f64).powi(2)).unwrap();
    /// assert_eq!((item, d2), (1, 1.0));
    /// ```
    #[must_use]
    pub fn build(boxes: &[Aabb3]) -> Bvh {
        let centre: Vec<Point3> = boxes.iter().map(Aabb3::center).collect();
        let mut order: Vec<u32> = (0..u32::try_from(boxes.len()).unwrap_or(u32::MAX)).collect();
        let mut nodes = Vec::with_capacity(2 * boxes.len() / LEAF_SIZE + 1);
        if !boxes.is_empty() {
            build_node(&mut nodes, boxes, &centre, &mut order, 0);
        }
        Bvh { nodes, order }
    }

    /// Number of items.
    #[must_use]
    pub fn len(&self) -> usize {
        self.order.len()
    }

    /// Whether there is no item.
    #[must_use]
    pub fn is_empty(&self) -> bool {
        self.order.is_empty()
    }

    /// The item with the smallest `dist2(item)` (a squared distance, never
    /// below the squared distance from `p` to the item's box) under `max_d2`,
    /// with that value; the lower item number on ties.
    pub fn nearest(&self, p: &Point3, max_d2: f64, mut dist2: impl FnMut(usize) -> f64) -> Option<(usize, f64)> {
        if self.nodes.is_empty() {
            return None;
        }
        let mut best: Option<(usize, f64)> = None;
        let mut bound = max_d2;
        let mut stack: Vec<(u32, f64)> = Vec::with_capacity(64);
        stack.push((0, self.nodes[0].distance_squared(p)));
        while let Some((id, d2)) = stack.pop() {
            if d2 > bound {
                continue;
            }
            let node = &self.nodes[id as usize];
            if node.count > 0 {
                let first = node.first_or_right as usize;
                for &item in &self.order[first..first + node.count as usize] {
                    let item = item as usize;
                    let d = dist2(item);
                    let better = match best {
                        None => d <= bound,
                        Some((b, bd)) => d.total_cmp(&bd).then(item.cmp(&b)).is_lt(),
                    };
                    if better {
                        best = Some((item, d));
                        bound = d;
                    }
                }
            } else {
                let (l, r) = (id + 1, node.first_or_right);
                let dl = self.nodes[l as usize].distance_squared(p);
                let dr = self.nodes[r as usize].distance_squared(p);
                // The nearer child pops first.
                if dl <= dr {
                    stack.push((r, dr));
                    stack.push((l, dl));
                } else {
                    stack.push((l, dl));
                    stack.push((r, dr));
                }
            }
        }
        best
    }

    /// Calls `visit(item)` for every item whose box meets `query` (closed), in
    /// leaf order.
    pub fn visit_overlapping(&self, query: &Aabb3, mut visit: impl FnMut(usize)) {
        if self.nodes.is_empty() {
            return;
        }
        let mut stack: Vec<u32> = vec![0];
        while let Some(id) = stack.pop() {
            let node = &self.nodes[id as usize];
            if !node.overlaps(query) {
                continue;
            }
            if node.count > 0 {
                let first = node.first_or_right as usize;
                for &item in &self.order[first..first + node.count as usize] {
                    visit(item as usize);
                }
            } else {
                stack.push(node.first_or_right);
                stack.push(id + 1);
            }
        }
    }

    /// Calls `visit(item)` for every item whose box the segment
    /// `origin + t dir`, `t` in `[t0, t1]`, may meet; `visit` returns a new
    /// (smaller) `t1` to prune with, or `None` to keep it.
    pub fn visit_ray(
        &self,
        origin: &Point3,
        dir: &Vec3,
        t0: f64,
        t1: f64,
        mut visit: impl FnMut(usize) -> Option<f64>,
    ) {
        if self.nodes.is_empty() {
            return;
        }
        let inv = Vec3::new(1.0 / dir.x, 1.0 / dir.y, 1.0 / dir.z);
        let mut hi = t1;
        let mut stack: Vec<u32> = vec![0];
        while let Some(id) = stack.pop() {
            let node = &self.nodes[id as usize];
            if node.slab(origin, &inv, t0, hi).is_none() {
                continue;
            }
            if node.count > 0 {
                let first = node.first_or_right as usize;
                for &item in &self.order[first..first + node.count as usize] {
                    if let Some(t) = visit(item as usize) {
                        hi = hi.min(t);
                    }
                }
            } else {
                stack.push(node.first_or_right);
                stack.push(id + 1);
            }
        }
    }
}

fn build_node(nodes: &mut Vec<Node>, boxes: &[Aabb3], centre: &[Point3], order: &mut [u32], offset: usize) -> usize {
    let mut min = [f64::INFINITY; 3];
    let mut max = [f64::NEG_INFINITY; 3];
    for &i in order.iter() {
        let b = &boxes[i as usize];
        for k in 0..3 {
            min[k] = min[k].min(b.min[k]);
            max[k] = max[k].max(b.max[k]);
        }
    }
    let me = nodes.len();
    let to_u32 = |v: usize| u32::try_from(v).unwrap_or(u32::MAX);
    if order.len() <= LEAF_SIZE {
        nodes.push(Node { min, max, first_or_right: to_u32(offset), count: to_u32(order.len()) });
        return me;
    }
    nodes.push(Node { min, max, first_or_right: 0, count: 0 });
    let ext = [max[0] - min[0], max[1] - min[1], max[2] - min[2]];
    let axis = if ext[0] >= ext[1] && ext[0] >= ext[2] {
        0
    } else if ext[1] >= ext[2] {
        1
    } else {
        2
    };
    let mid = order.len() / 2;
    order.select_nth_unstable_by(mid, |&a, &b| {
        centre[a as usize][axis].total_cmp(&centre[b as usize][axis]).then(a.cmp(&b))
    });
    let (left, right) = order.split_at_mut(mid);
    build_node(nodes, boxes, centre, left, offset);
    let r = build_node(nodes, boxes, centre, right, offset + mid);
    nodes[me].first_or_right = to_u32(r);
    me
}
