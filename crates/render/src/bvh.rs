//! Bounding volume hierarchy over a mesh's triangles: binned surface-area-heuristic build (Wald
//! 2007, "On fast Construction of SAH-based Bounding Volume Hierarchies", 12 bins per axis) and
//! front-to-back traversal with the Möller–Trumbore ray–triangle test (Möller & Trumbore 1997).
//!
//! Written here rather than taken from the `bvh` crate because the renderer needs the *nearest* hit
//! with early termination (children visited near-first, the ray's t_max shrinking as hits are found)
//! and any-hit queries for shadows; `bvh` 0.13 returns every shape whose box the ray crosses and
//! leaves the ordering and the triangle tests to the caller. Nodes are a flat depth-first array
//! (the first child follows its parent), triangles are stored re-ordered with their edge vectors.

use glam::DVec3;

use crate::mesh::{Aabb, Mesh};

/// A ray: origin \[mm\] and unit direction.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Ray {
    /// Origin \[mm\].
    pub origin: DVec3,
    /// Unit direction.
    pub dir: DVec3,
}

/// The nearest intersection of a ray with the mesh.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Hit {
    /// Distance along the ray \[mm\].
    pub t: f64,
    /// Index of the triangle in the mesh.
    pub triangle: u32,
    /// Barycentric coordinates (u, v) of the hit: p = (1 − u − v)·v0 + u·v1 + v·v2.
    pub u: f64,
    /// See `u`.
    pub v: f64,
}

#[derive(Debug, Clone, Copy)]
struct Node {
    bounds: Aabb,
    /// Leaf: first triangle (in `tris`); interior: index of the second child.
    offset: u32,
    /// Leaf: triangle count (> 0); interior: 0.
    count: u16,
    /// Interior: split axis.
    axis: u8,
}

#[derive(Debug, Clone, Copy)]
struct Tri {
    v0: DVec3,
    e1: DVec3,
    e2: DVec3,
    index: u32,
}

/// The hierarchy. Build with [`Bvh::new`]; query with [`Bvh::intersect`] and [`Bvh::occluded`].
#[derive(Debug, Clone)]
pub struct Bvh {
    nodes: Vec<Node>,
    tris: Vec<Tri>,
}

const BINS: usize = 12;
const MAX_LEAF: usize = 4;
/// SAH cost of a traversal step relative to one triangle test.
const TRAVERSAL_COST: f64 = 1.0;
/// Below this depth splits follow the SAH; deeper ones split at the median (stack of 64 suffices).
const MAX_SAH_DEPTH: usize = 32;

struct BuildItem {
    bounds: Aabb,
    centroid: DVec3,
    index: u32,
}

impl Bvh {
    /// Builds the hierarchy over every triangle of `mesh`.
    pub fn new(mesh: &Mesh) -> Self {
        let mut items: Vec<BuildItem> = (0..mesh.triangles().len())
            .map(|t| {
                let [a, b, c] = mesh.corners(t);
                let bounds = Aabb::EMPTY.grow(a).grow(b).grow(c);
                BuildItem {
                    bounds,
                    centroid: bounds.center(),
                    index: t as u32,
                }
            })
            .collect();
        let mut nodes = Vec::with_capacity(2 * items.len() / MAX_LEAF + 1);
        build(&mut items, 0, 0, &mut nodes);
        let tris = items
            .iter()
            .map(|it| {
                let [a, b, c] = mesh.corners(it.index as usize);
                Tri {
                    v0: a,
                    e1: b - a,
                    e2: c - a,
                    index: it.index,
                }
            })
            .collect();
        Self { nodes, tris }
    }

    /// Bounds of the whole mesh.
    pub fn bounds(&self) -> Aabb {
        self.nodes[0].bounds
    }

    /// Number of nodes.
    pub fn node_count(&self) -> usize {
        self.nodes.len()
    }

    /// The nearest hit with t in (t_min, t_max).
    pub fn intersect(&self, ray: &Ray, t_min: f64, t_max: f64) -> Option<Hit> {
        let inv = ray.dir.recip();
        let neg = [inv.x < 0.0, inv.y < 0.0, inv.z < 0.0];
        let mut best: Option<Hit> = None;
        let mut t_far = t_max;
        let mut stack = [0u32; 64];
        let mut sp = 0usize;
        let mut node = 0usize;
        loop {
            let n = &self.nodes[node];
            if slab_test(&n.bounds, ray.origin, inv, t_min, t_far) {
                if n.count > 0 {
                    let first = n.offset as usize;
                    for tri in &self.tris[first..first + n.count as usize] {
                        if let Some((t, u, v)) = intersect_tri(tri, ray, t_min, t_far) {
                            t_far = t;
                            best = Some(Hit {
                                t,
                                triangle: tri.index,
                                u,
                                v,
                            });
                        }
                    }
                } else {
                    // Visit the child on the ray's near side first.
                    let (near, far) = if neg[n.axis as usize] {
                        (n.offset as usize, node + 1)
                    } else {
                        (node + 1, n.offset as usize)
                    };
                    stack[sp] = far as u32;
                    sp += 1;
                    node = near;
                    continue;
                }
            }
            if sp == 0 {
                break;
            }
            sp -= 1;
            node = stack[sp] as usize;
        }
        best
    }

    /// Whether anything lies on the ray with t in (t_min, t_max) (shadow rays).
    pub fn occluded(&self, ray: &Ray, t_min: f64, t_max: f64) -> bool {
        let inv = ray.dir.recip();
        let mut stack = [0u32; 64];
        let mut sp = 0usize;
        let mut node = 0usize;
        loop {
            let n = &self.nodes[node];
            if slab_test(&n.bounds, ray.origin, inv, t_min, t_max) {
                if n.count > 0 {
                    let first = n.offset as usize;
                    for tri in &self.tris[first..first + n.count as usize] {
                        if intersect_tri(tri, ray, t_min, t_max).is_some() {
                            return true;
                        }
                    }
                } else {
                    stack[sp] = n.offset;
                    sp += 1;
                    node += 1;
                    continue;
                }
            }
            if sp == 0 {
                return false;
            }
            sp -= 1;
            node = stack[sp] as usize;
        }
    }
}

#[inline(always)]
fn slab_test(b: &Aabb, o: DVec3, inv: DVec3, t_min: f64, t_max: f64) -> bool {
    let t0 = (b.min - o) * inv;
    let t1 = (b.max - o) * inv;
    let lo = t0.min(t1);
    let hi = t0.max(t1);
    // NaN (0 · ∞ for a ray in a box face's plane) drops out of max/min in favour of the other operand.
    let enter = lo.max_element().max(t_min);
    let exit = hi.min_element().min(t_max);
    enter <= exit
}

/// Möller & Trumbore 1997, "Fast, Minimum Storage Ray/Triangle Intersection": (t, u, v) or None.
#[inline(always)]
fn intersect_tri(tri: &Tri, ray: &Ray, t_min: f64, t_max: f64) -> Option<(f64, f64, f64)> {
    let p = ray.dir.cross(tri.e2);
    let det = tri.e1.dot(p);
    if det.abs() < 1e-14 * tri.e1.length_squared().max(tri.e2.length_squared()) {
        return None;
    }
    let inv_det = 1.0 / det;
    let s = ray.origin - tri.v0;
    let u = s.dot(p) * inv_det;
    if !(0.0..=1.0).contains(&u) {
        return None;
    }
    let q = s.cross(tri.e1);
    let v = ray.dir.dot(q) * inv_det;
    if v < 0.0 || u + v > 1.0 {
        return None;
    }
    let t = tri.e2.dot(q) * inv_det;
    (t > t_min && t < t_max).then_some((t, u, v))
}

/// Recursive binned-SAH build; returns the index of the subtree's root. Nodes are appended depth
/// first, so an interior node's first child is the next node.
fn build(items: &mut [BuildItem], start: usize, depth: usize, nodes: &mut Vec<Node>) -> usize {
    let bounds = items.iter().fold(Aabb::EMPTY, |b, it| b.union(it.bounds));
    let me = nodes.len();
    nodes.push(Node {
        bounds,
        offset: 0,
        count: 0,
        axis: 0,
    });
    let n = items.len();
    let leaf = |nodes: &mut Vec<Node>| {
        nodes[me].offset = start as u32;
        nodes[me].count = n as u16;
    };
    let cbounds = items.iter().fold(Aabb::EMPTY, |b, it| b.grow(it.centroid));
    let ext = cbounds.extent();
    let axis = if ext.x >= ext.y && ext.x >= ext.z {
        0
    } else if ext.y >= ext.z {
        1
    } else {
        2
    };
    let leaf_cost = n as f64;
    if n <= MAX_LEAF || (ext[axis] <= 0.0 && n <= MAX_LEAF * 4) {
        leaf(nodes);
        return me;
    }
    // Binned SAH over the three axes.
    let mut best = (f64::INFINITY, 0usize, 0usize);
    for ax in 0..3 {
        if ext[ax] <= 0.0 {
            continue;
        }
        let scale = BINS as f64 / ext[ax];
        let bin_of = |c: DVec3| (((c[ax] - cbounds.min[ax]) * scale) as usize).min(BINS - 1);
        let mut counts = [0usize; BINS];
        let mut boxes = [Aabb::EMPTY; BINS];
        for it in items.iter() {
            let b = bin_of(it.centroid);
            counts[b] += 1;
            boxes[b] = boxes[b].union(it.bounds);
        }
        let mut right_area = [0.0; BINS];
        let mut right_count = [0usize; BINS];
        let (mut acc_b, mut acc_n) = (Aabb::EMPTY, 0);
        for b in (1..BINS).rev() {
            acc_b = acc_b.union(boxes[b]);
            acc_n += counts[b];
            right_area[b] = acc_b.area();
            right_count[b] = acc_n;
        }
        let (mut acc_b, mut acc_n) = (Aabb::EMPTY, 0);
        for split in 1..BINS {
            acc_b = acc_b.union(boxes[split - 1]);
            acc_n += counts[split - 1];
            if acc_n == 0 || right_count[split] == 0 {
                continue;
            }
            let cost = acc_n as f64 * acc_b.area() + right_count[split] as f64 * right_area[split];
            if cost < best.0 {
                best = (cost, ax, split);
            }
        }
    }
    let area = bounds.area().max(1e-300);
    let split_cost = TRAVERSAL_COST + best.0 / area;
    let mid = if depth >= MAX_SAH_DEPTH {
        // Deep trees only arise from pathological inputs: median split keeps the depth (and the
        // traversal stack) bounded by log2 of the triangle count.
        items.select_nth_unstable_by(n / 2, |a, b| a.centroid[axis].total_cmp(&b.centroid[axis]));
        best.1 = axis;
        n / 2
    } else if best.0.is_finite() && (split_cost < leaf_cost || n > MAX_LEAF * 4) {
        let (ax, split) = (best.1, best.2);
        let scale = BINS as f64 / ext[ax];
        let min = cbounds.min[ax];
        partition(items, |it| {
            ((((it.centroid[ax] - min) * scale) as usize).min(BINS - 1)) < split
        })
    } else if n <= MAX_LEAF * 4 {
        leaf(nodes);
        return me;
    } else {
        // All centroids coincide on every axis: split in the middle of the list.
        n / 2
    };
    let mid = if mid == 0 || mid == n { n / 2 } else { mid };
    nodes[me].axis = best.1 as u8;
    let (left, right) = items.split_at_mut(mid);
    build(left, start, depth + 1, nodes);
    let second = build(right, start + mid, depth + 1, nodes);
    nodes[me].offset = second as u32;
    me
}

fn partition<T>(items: &mut [T], pred: impl Fn(&T) -> bool) -> usize {
    let mut i = 0;
    for j in 0..items.len() {
        if pred(&items[j]) {
            items.swap(i, j);
            i += 1;
        }
    }
    i
}
