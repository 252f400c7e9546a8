//! Traversal of the [`Bvh`]: the closest hit and any hit along a ray, nearest child first,
//! culling on pop by the entry distance stored with each pushed node; compiled with and without
//! the instance step (a two-level walk into an instanced mesh's own tree), behind the widest
//! SIMD the machine has.

use super::*;

impl Bvh {
    /// Closest hit along `origin + t dir`, t in (0, t_max).
    pub fn closest_hit(&self, origin: Vec3, dir: Vec3, t_max: f32) -> SurfaceHit {
        let hit = self.closest_prim(origin, dir, t_max);
        if hit.prim == NONE {
            return SurfaceHit::miss();
        }
        self.surface(hit, origin, dir)
    }

    /// The primitive hit first along `origin + t dir`, t in (0, t_max), and its t; `NONE`
    /// for a miss. Of a one-level tree's primitives hit at exactly the same t, the smallest id
    /// (with instances, see `closest_in`).
    #[inline]
    pub fn closest_prim(&self, origin: Vec3, dir: Vec3, t_max: f32) -> PrimHit {
        if self.instances.is_empty() {
            let (prim, t) = self.closest_one_level(origin, dir, t_max);
            PrimHit {
                prim,
                instance: NONE,
                t,
            }
        } else {
            self.closest_two_level(origin, dir, t_max)
        }
    }

    widest_simd! {
        /// [`Bvh::closest_prim`] of a tree without instances: the primitive and t.
        fn closest_one_level(&self, origin: Vec3, dir: Vec3, t_max: f32) -> (u32, f32)
            = closest_one_level_any_cpu, closest_one_level_avx512, closest_one_level_avx2
    }

    #[inline(always)]
    fn closest_one_level_any_cpu(&self, origin: Vec3, dir: Vec3, t_max: f32) -> (u32, f32) {
        let Some(root) = self.root else {
            return (NONE, t_max);
        };
        let mut no_instance = NONE;
        self.closest_in::<false, Solid>(root, origin, dir, (NONE, t_max), &mut no_instance, Solid)
    }

    widest_simd! {
        /// [`Bvh::closest_prim`] of a tree with instances.
        fn closest_two_level(&self, origin: Vec3, dir: Vec3, t_max: f32) -> PrimHit
            = closest_two_level_any_cpu, closest_two_level_avx512, closest_two_level_avx2
    }

    #[inline(always)]
    fn closest_two_level_any_cpu(&self, origin: Vec3, dir: Vec3, t_max: f32) -> PrimHit {
        self.closest_from_root::<true, Solid>(origin, dir, t_max, Solid)
    }

    /// The closest hit from the root (a miss at `t_max` in an empty tree), with the instance
    /// step where `INSTANCES`, counting the candidates `presence` says are there.
    #[inline(always)]
    fn closest_from_root<const INSTANCES: bool, P: Presence>(
        &self,
        origin: Vec3,
        dir: Vec3,
        t_max: f32,
        presence: P,
    ) -> PrimHit {
        let mut instance = NONE;
        let Some(root) = self.root else {
            return PrimHit {
                prim: NONE,
                instance,
                t: t_max,
            };
        };
        let best = (NONE, t_max);
        let (prim, t) =
            self.closest_in::<INSTANCES, P>(root, origin, dir, best, &mut instance, presence);
        PrimHit { prim, instance, t }
    }

    /// The closest hit in the subtree `start` of a ray that has found `best` = (primitive, t)
    /// so far (`NONE` and t_max at first): the primitive and t, with the instance step compiled
    /// in where `INSTANCES` (the hit's instance is then written to `best_instance`, `NONE` for
    /// this tree's own primitives; the one-level loop never touches it).
    ///
    /// Of primitives hit at exactly the same t, the least (instance, id) wins (this tree's own
    /// primitives counting as instance `NONE`, after every instance), so the answer is the
    /// least (t, instance, id) whatever order the nodes are visited in: packet traversal
    /// (`bvh_packet.rs`) gives the same hits.
    #[inline(always)]
    pub(in crate::cpu) fn closest_in<const INSTANCES: bool, P: Presence>(
        &self,
        start: u32,
        origin: Vec3,
        dir: Vec3,
        (mut best, mut best_t): (u32, f32),
        best_instance: &mut u32,
        presence: P,
    ) -> (u32, f32) {
        let ray = Ray4::new(origin, dir);
        // Not zero-filled (3 KiB per ray): entries below `sp` are always written first.
        let mut stack = [const { MaybeUninit::<(u32, f32)>::uninit() }; STACK];
        let mut sp = 0;
        let mut current = start;
        loop {
            if current & LEAF == 0 {
                let node = &self.nodes[current as usize];
                let (near, hit) = ray.slab(&node.boxes, best_t);
                let mut bits = (hit & Mask::from_bitmask(node.used as u64)).to_bitmask() as u32;
                if bits != 0 {
                    let near = near.to_array();
                    if bits & (bits - 1) == 0 {
                        current = node.child[bits.trailing_zeros() as usize];
                        continue;
                    }
                    // Two or more children: sort by entry distance, go to the nearest and
                    // push the others farthest first. The build bounds the depth, so the
                    // stack never overflows.
                    let mut order = [(0u32, 0.0f32); WIDTH];
                    let mut k = 0;
                    while bits != 0 {
                        let lane = bits.trailing_zeros() as usize;
                        bits &= bits - 1;
                        let mut j = k;
                        while j > 0 && order[j - 1].1 > near[lane] {
                            order[j] = order[j - 1];
                            j -= 1;
                        }
                        order[j] = (node.child[lane], near[lane]);
                        k += 1;
                    }
                    for &entry in order[1..k].iter().rev() {
                        stack[sp].write(entry);
                        sp += 1;
                        self.prefetch(entry.0);
                    }
                    current = order[0].0;
                    continue;
                }
            } else {
                let (blocks, spheres) = self.leaf_contents(current);
                for block in &self.blocks[blocks] {
                    let limit = tie_limit(best, best_t);
                    let t = ray.triangles(&block.triangles, 0.0, limit).to_array();
                    for (&t, &id) in t.iter().zip(&block.id) {
                        // Missed lanes are -1; hits are below `limit` as it was at the call.
                        if t >= 0.0
                            && (t < best_t
                                || (t == best_t
                                    && own_tie_won::<INSTANCES>(id, best, best_instance)))
                            && (P::SOLID || self.triangle_present(presence, id, origin, dir))
                        {
                            best_t = t;
                            best = id;
                            if INSTANCES {
                                *best_instance = NONE;
                            }
                        }
                    }
                }
                for block in &self.sphere_blocks[spheres] {
                    let limit = tie_limit(best, best_t);
                    let t = ray.spheres(&block.spheres, 0.0, limit).to_array();
                    for (&t, &id) in t.iter().zip(&block.id) {
                        if t >= 0.0
                            && (t < best_t
                                || (t == best_t
                                    && own_tie_won::<INSTANCES>(id, best, best_instance)))
                        {
                            best_t = t;
                            best = id;
                            if INSTANCES {
                                *best_instance = NONE;
                            }
                        }
                    }
                }
                if INSTANCES {
                    for &i in &self.leaf_instances[self.instances_of_leaf(current)] {
                        let instance = &self.instances[i as usize];
                        let (o, d) = ray_to_object(instance, origin, dir);
                        let mesh = &self.meshes[self.instance_meshes[i as usize] as usize];
                        let Some(mesh_root) = mesh.root else { continue };
                        let mut no_instance = NONE;
                        let (prim, t) = mesh.closest_in::<false, P>(
                            mesh_root,
                            o,
                            d,
                            (tie_seeker(best), best_t),
                            &mut no_instance,
                            presence.in_instance(i),
                        );
                        if found(prim) && (t < best_t || (t == best_t && i < *best_instance)) {
                            best_t = t;
                            best = prim;
                            *best_instance = i;
                        }
                    }
                }
            }
            // Pop the next node still in front of the closest hit: its stored entry distance
            // against the padded far bound, exactly the slab test's verdict with today's t_max.
            loop {
                if sp == 0 {
                    return (best, best_t);
                }
                sp -= 1;
                // SAFETY: entry `sp` was written by a push (sp only grows by writing).
                let (r, near) = unsafe { stack[sp].assume_init() };
                if near <= best_t * SLAB_PAD {
                    current = r;
                    break;
                }
            }
        }
    }

    /// Whether anything is hit along `origin + t dir`, t in (0, t_max).
    #[inline]
    pub fn any_hit(&self, origin: Vec3, dir: Vec3, t_max: f32) -> bool {
        if self.instances.is_empty() {
            self.any_one_level(origin, dir, t_max)
        } else {
            self.any_two_level(origin, dir, t_max)
        }
    }

    widest_simd! {
        /// [`Bvh::any_hit`] of a tree without instances.
        fn any_one_level(&self, origin: Vec3, dir: Vec3, t_max: f32) -> bool
            = any_one_level_any_cpu, any_one_level_avx512, any_one_level_avx2
    }

    #[inline(always)]
    fn any_one_level_any_cpu(&self, origin: Vec3, dir: Vec3, t_max: f32) -> bool {
        // Not `is_some_and`: a closure is not compiled with the caller's target features.
        match self.root {
            Some(root) => self.any_in::<false, Solid>(root, origin, dir, t_max, Solid),
            None => false,
        }
    }

    widest_simd! {
        /// [`Bvh::any_hit`] of a tree with instances.
        fn any_two_level(&self, origin: Vec3, dir: Vec3, t_max: f32) -> bool
            = any_two_level_any_cpu, any_two_level_avx512, any_two_level_avx2
    }

    #[inline(always)]
    fn any_two_level_any_cpu(&self, origin: Vec3, dir: Vec3, t_max: f32) -> bool {
        // Not `is_some_and`: a closure is not compiled with the caller's target features.
        match self.root {
            Some(root) => self.any_in::<true, Solid>(root, origin, dir, t_max, Solid),
            None => false,
        }
    }

    /// [`Bvh::any_hit`] in the subtree `start`, with the instance step compiled in where
    /// `INSTANCES`.
    #[inline(always)]
    pub(in crate::cpu) fn any_in<const INSTANCES: bool, P: Presence>(
        &self,
        start: u32,
        origin: Vec3,
        dir: Vec3,
        t_max: f32,
        presence: P,
    ) -> bool {
        let ray = Ray4::new(origin, dir);
        let mut stack = [const { MaybeUninit::<u32>::uninit() }; STACK];
        let mut sp = 0;
        let mut current = start;
        loop {
            if current & LEAF == 0 {
                let node = &self.nodes[current as usize];
                let (_, hit) = ray.slab(&node.boxes, t_max);
                let mut bits = (hit & Mask::from_bitmask(node.used as u64)).to_bitmask() as u32;
                while bits != 0 {
                    let lane = bits.trailing_zeros() as usize;
                    bits &= bits - 1;
                    stack[sp].write(node.child[lane]);
                    sp += 1;
                    self.prefetch(node.child[lane]);
                }
            } else {
                let (blocks, spheres) = self.leaf_contents(current);
                for block in &self.blocks[blocks] {
                    let t = ray.triangles(&block.triangles, 0.0, t_max).to_array();
                    if P::SOLID {
                        if t.iter().any(|&t| t >= 0.0) {
                            return true;
                        }
                    } else {
                        for (&t, &id) in t.iter().zip(&block.id) {
                            if t >= 0.0 && self.triangle_present(presence, id, origin, dir) {
                                return true;
                            }
                        }
                    }
                }
                for block in &self.sphere_blocks[spheres] {
                    let t = ray.spheres(&block.spheres, 0.0, t_max);
                    if t.to_array().iter().any(|&t| t >= 0.0) {
                        return true;
                    }
                }
                if INSTANCES {
                    for &i in &self.leaf_instances[self.instances_of_leaf(current)] {
                        let (o, d) = ray_to_object(&self.instances[i as usize], origin, dir);
                        let mesh = &self.meshes[self.instance_meshes[i as usize] as usize];
                        let Some(mesh_root) = mesh.root else { continue };
                        if mesh.any_in::<false, P>(mesh_root, o, d, t_max, presence.in_instance(i))
                        {
                            return true;
                        }
                    }
                }
            }
            if sp == 0 {
                return false;
            }
            sp -= 1;
            // SAFETY: entry `sp` was written by a push (sp only grows by writing).
            current = unsafe { stack[sp].assume_init() };
        }
    }

    /// Whether primitive `id` (a triangle: blocks hold only triangles) is there for
    /// `presence`, met by `origin + t dir` in this tree's space.
    #[inline(always)]
    pub(in crate::cpu) fn triangle_present<P: Presence>(
        &self,
        presence: P,
        id: u32,
        origin: Vec3,
        dir: Vec3,
    ) -> bool {
        let index = id as usize - self.spheres.len();
        presence.present(&self.triangles[index], index as u32, origin, dir)
    }

    /// [`Bvh::closest_hit`] where materials may have holes: candidates that `tables` say are not
    /// there are passed through (`holes.rs`).
    pub fn closest_hit_through(
        &self,
        origin: Vec3,
        dir: Vec3,
        t_max: f32,
        tables: &HoleTables<'_>,
    ) -> SurfaceHit {
        let hit = self.closest_through(origin, dir, t_max, tables);
        if hit.prim == NONE {
            return SurfaceHit::miss();
        }
        self.surface(hit, origin, dir)
    }

    widest_simd! {
        /// The primitive of [`Bvh::closest_hit_through`].
        fn closest_through(&self, origin: Vec3, dir: Vec3, t_max: f32, tables: &HoleTables<'_>)
            -> PrimHit = closest_through_any_cpu, closest_through_avx512, closest_through_avx2
    }

    #[inline(always)]
    fn closest_through_any_cpu(
        &self,
        origin: Vec3,
        dir: Vec3,
        t_max: f32,
        tables: &HoleTables<'_>,
    ) -> PrimHit {
        let holes = Holes::of_ray(*tables, origin, dir);
        if self.instances.is_empty() {
            self.closest_from_root::<false, Holes>(origin, dir, t_max, holes)
        } else {
            self.closest_from_root::<true, Holes>(origin, dir, t_max, holes)
        }
    }

    widest_simd! {
        /// [`Bvh::any_hit`] where materials may have holes (as [`Bvh::closest_hit_through`]).
        pub fn any_hit_through(&self, origin: Vec3, dir: Vec3, t_max: f32, tables: &HoleTables<'_>)
            -> bool = any_through_any_cpu, any_through_avx512, any_through_avx2
    }

    #[inline(always)]
    fn any_through_any_cpu(
        &self,
        origin: Vec3,
        dir: Vec3,
        t_max: f32,
        tables: &HoleTables<'_>,
    ) -> bool {
        let Some(root) = self.root else {
            return false;
        };
        let holes = Holes::of_ray(*tables, origin, dir);
        if self.instances.is_empty() {
            self.any_in::<false, Holes>(root, origin, dir, t_max, holes)
        } else {
            self.any_in::<true, Holes>(root, origin, dir, t_max, holes)
        }
    }

    /// Starts loading the node or first triangle block of reference `r` into the cache: a
    /// pushed child is usually popped soon, and incoherent rays on large meshes wait on memory
    /// (its effect is measured in docs/performance.md).
    #[inline(always)]
    pub(in crate::cpu) fn prefetch(&self, r: u32) {
        #[cfg(target_arch = "x86_64")]
        {
            use std::arch::x86_64::{_mm_prefetch, _MM_HINT_T0};
            let (start, bytes) = if r & LEAF == 0 {
                let node = self.nodes.as_ptr().wrapping_add(r as usize);
                (node as *const i8, std::mem::size_of::<WideNode>())
            } else if r & LISTED == 0 {
                let first = (r & ((1 << BLOCK_BITS) - 1)) as usize;
                let block = self.blocks.as_ptr().wrapping_add(first);
                (block as *const i8, std::mem::size_of::<TriangleBlock>())
            } else {
                return;
            };
            for line in (0..bytes).step_by(64) {
                // SAFETY: a prefetch is a hint; it never faults, whatever the address.
                unsafe { _mm_prefetch(start.wrapping_add(line), _MM_HINT_T0) };
            }
        }
    }

    /// The triangle blocks and the sphere blocks of leaf reference `r`.
    #[inline(always)]
    pub(in crate::cpu) fn leaf_contents(&self, r: u32) -> (Range<usize>, Range<usize>) {
        if r & LISTED == 0 {
            let first = (r & ((1 << BLOCK_BITS) - 1)) as usize;
            let count = ((r >> BLOCK_BITS) & 3) as usize + 1;
            (first..first + count, 0..0)
        } else {
            let leaf = &self.leaves[(r & !(LEAF | LISTED)) as usize];
            let first = leaf.first_block as usize;
            let sphere = leaf.first_sphere_block as usize;
            (
                first..first + leaf.triangle_blocks as usize,
                sphere..sphere + leaf.sphere_blocks as usize,
            )
        }
    }

    /// The range of [`Bvh::leaf_instances`] that leaf reference `r` holds.
    #[inline(always)]
    pub(in crate::cpu) fn instances_of_leaf(&self, r: u32) -> Range<usize> {
        if r & LISTED == 0 {
            0..0
        } else {
            let (first, end) = self.leaf_instance_ranges[(r & !(LEAF | LISTED)) as usize];
            first as usize..end as usize
        }
    }
}

/// `best` as an instance's mesh search starts from it: [`TIE`] where something is hit.
#[inline(always)]
fn tie_seeker(best: u32) -> u32 {
    if best == NONE {
        NONE
    } else {
        TIE
    }
}

/// Whether a search's answer is a primitive (neither a miss nor [`TIE`]).
#[inline(always)]
fn found(prim: u32) -> bool {
    prim < TIE
}

/// Whether this tree's primitive `id`, hit at exactly the t of the ray's best hit so far
/// (`best`, on instance `best_instance` or on this tree's own primitives, `NONE`; a tree
/// traversed without `INSTANCES` has only its own), wins the tie: the least (instance, id)
/// wins, this tree's own primitives counting as instance `NONE`.
#[inline(always)]
fn own_tie_won<const INSTANCES: bool>(id: u32, best: u32, best_instance: &u32) -> bool {
    (!INSTANCES || *best_instance == NONE) && id < best
}

/// The bound below which a leaf's hits are accepted by a ray whose closest hit so far is
/// `best` at `best_t`: `best_t` itself while nothing is hit (t_max is excluded), else the next
/// float above it, so that a hit at exactly `best_t` is seen and the smaller id can win.
#[inline(always)]
fn tie_limit(best: u32, best_t: f32) -> f32 {
    // Once something is hit, best_t is positive and finite: the next float is the next pattern.
    f32::from_bits(best_t.to_bits() + (best != NONE) as u32)
}
