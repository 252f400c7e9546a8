//! The packets' paths that split at their first vertex (`kernel::split`): the jobs a sample's
//! path becomes, and the continuations that wait to leave their first vertex. Continuation 0
//! goes on in its sample's lane; continuations 1 to n - 1 draw their first vertex's samples in
//! the SIMD fill of a later round, in query slots no lane uses that round (or sixteen at a
//! time when they pile up), then wait for a lane with their rays ready. Each draws exactly the
//! numbers `kernel::split::render_split_sample` draws one at a time (the fill's contract), so
//! the image is the one-path loop's.

use super::packet::LANES;
use super::packet_vertices::fill_vertex_samples;
use kernel::features::FeatureSet;
use kernel::path::PathState;
use kernel::rng::SampleRng;
use kernel::split::FirstVertex;
use kernel::vertex_samples::{VertexQuery, VertexSamples};
use kernel::SceneView;
use std::collections::VecDeque;

/// What a path of the packets computes for its sample: the whole path or, where the sample's
/// path splits at its first vertex, its continuation `j`.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub(super) enum Part {
    Whole,
    Continuation(u32),
}

/// A path of the packets at work for sample slot `k`.
#[derive(Clone, Copy, Debug)]
pub(super) struct Job {
    pub k: usize,
    pub part: Part,
    pub path: PathState,
}

/// A sample's path forked at its first vertex, while some of its continuations have not left.
struct Fork {
    vertex: FirstVertex,
    k: usize,
    n: u32,
    left_to_leave: u32,
}

/// A continuation given query slot `slot` of this round's fill: its fork, its index, its path
/// and query at the vertex.
#[derive(Clone, Copy)]
pub(super) struct Leaving {
    slot: usize,
    fork: usize,
    j: u32,
    path: PathState,
    query: VertexQuery,
}

/// The queries of a round's fill, one slot per lane.
pub(super) type Queries = [Option<(SampleRng, VertexQuery)>; LANES];

/// The continuations 1 to n - 1 of forked paths that have yet to leave their first vertex.
#[derive(Default)]
pub(super) struct Forks {
    /// Fork records, reused through `free`.
    records: Vec<Fork>,
    free: Vec<usize>,
    /// (record, j), first come first served.
    queue: VecDeque<(usize, u32)>,
}

impl Forks {
    /// Sample slot `k`'s path, at its first vertex `vertex`, splits in `n`: queues its
    /// continuations 1 to n - 1.
    pub fn fork(&mut self, k: usize, n: u32, vertex: FirstVertex) {
        let record = Fork {
            vertex,
            k,
            n,
            left_to_leave: n - 1,
        };
        let f = match self.free.pop() {
            Some(f) => {
                self.records[f] = record;
                f
            }
            None => {
                self.records.push(record);
                self.records.len() - 1
            }
        };
        self.queue.extend((1..n).map(|j| (f, j)));
    }

    /// Continuations queued.
    pub fn queued(&self) -> usize {
        self.queue.len()
    }

    /// Gives queued continuations the empty slots of `queries`, onto `leaving` (emptied
    /// first).
    pub fn take_slots(
        &mut self,
        scene: &SceneView,
        queries: &mut Queries,
        leaving: &mut Vec<Leaving>,
    ) {
        leaving.clear();
        for (slot, query_slot) in queries.iter_mut().enumerate() {
            if query_slot.is_some() {
                continue;
            }
            let Some((fork, j)) = self.queue.pop_front() else {
                break;
            };
            let record = &self.records[fork];
            let (path, query) = record.vertex.at_vertex(scene, record.n, j);
            *query_slot = Some((path.rng, query));
            leaving.push(Leaving {
                slot,
                fork,
                j,
                path,
                query,
            });
        }
    }

    /// The continuations `leaving` after their vertex, with the samples the fill gave their
    /// slots: pushed onto `pending`, their rays waiting.
    pub fn leave<F: FeatureSet>(
        &mut self,
        features: F,
        scene: &SceneView,
        leaving: &[Leaving],
        samples: &[VertexSamples; LANES],
        pending: &mut Vec<Job>,
    ) {
        for entry in leaving {
            let Leaving {
                slot,
                fork,
                j,
                mut path,
                query,
            } = *entry;
            let record = &mut self.records[fork];
            let (hit, material) = (&record.vertex.hit, &record.vertex.material);
            path.vertex(features, scene, hit, material, &query, &samples[slot]);
            FirstVertex::left(scene, record.n, j, &mut path);
            pending.push(Job {
                k: record.k,
                part: Part::Continuation(j),
                path,
            });
            record.left_to_leave -= 1;
            if record.left_to_leave == 0 {
                self.free.push(fork);
            }
        }
    }

    /// Sixteen queued continuations (or all, if fewer) leave their vertex in a fill of their
    /// own, onto `pending`.
    pub fn leave_sixteen<F: FeatureSet>(
        &mut self,
        features: F,
        scene: &SceneView,
        pending: &mut Vec<Job>,
    ) {
        let mut queries = [None; LANES];
        let mut leaving = Vec::with_capacity(LANES);
        self.take_slots(scene, &mut queries, &mut leaving);
        let samples = fill_vertex_samples(&queries, scene.lights);
        self.leave(features, scene, &leaving, &samples, pending);
    }
}
