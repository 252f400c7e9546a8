//! Which candidate hits a packet's traversal counts, lane by lane: every one ([`Solid`], the
//! loop as it always was, the question compiled out), or those the materials say are there for
//! that lane's world-space ray ([`LaneHoles`]: glTF's MASK and BLEND, `kernel::opacity`), the
//! one-ray traversal's [`Presence`] asked lane by lane, so that each lane's answer is the one
//! its ray gets alone.

use super::bvh::{HoleTables, Holes, Presence, Solid};
use super::packet::RayPacket;
use kernel::scene::NONE;

/// The candidates that count for each lane of a packet.
pub trait LanePresence: Copy {
    /// Every candidate counts: the packet's leaf tests skip the question.
    const SOLID: bool;
    /// The one-ray answer of a lane.
    type Lane: Presence;
    /// The answer for lane `lane`'s ray.
    fn lane(&self, lane: usize) -> Self::Lane;
    /// The answers inside the mesh of instance `instance`.
    fn in_instance(&self, instance: u32) -> Self;
}

impl LanePresence for Solid {
    const SOLID: bool = true;
    type Lane = Solid;
    #[inline(always)]
    fn lane(&self, _: usize) -> Solid {
        Solid
    }
    #[inline(always)]
    fn in_instance(&self, _: u32) -> Self {
        Solid
    }
}

/// The candidates of the packet `world`'s rays (world space, whatever tree the traversal is
/// in) that the materials of `tables` say are there; `instance` is the instance whose mesh the
/// traversal is in (`NONE` at the top level).
#[derive(Clone, Copy)]
pub struct LaneHoles<'a> {
    tables: HoleTables<'a>,
    world: &'a RayPacket,
    instance: u32,
}

impl<'a> LaneHoles<'a> {
    /// The candidates of the world-space packet `world` at the top level of the tree.
    pub fn of_packet(tables: HoleTables<'a>, world: &'a RayPacket) -> Self {
        LaneHoles {
            tables,
            world,
            instance: NONE,
        }
    }
}

impl<'a> LanePresence for LaneHoles<'a> {
    const SOLID: bool = false;
    type Lane = Holes<'a>;
    #[inline(always)]
    fn lane(&self, lane: usize) -> Holes<'a> {
        let (origin, dir) = self.world.lane(lane);
        Holes::of_ray(self.tables, origin, dir).in_instance(self.instance)
    }
    #[inline(always)]
    fn in_instance(&self, instance: u32) -> Self {
        LaneHoles { instance, ..*self }
    }
}
