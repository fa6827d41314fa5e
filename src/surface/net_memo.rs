//! A per-thread memo of rebuilt control nets: each triangle's whole net and corner normals
//! ([`Local`]), as the G² surface rebuilds them from its stored offsets, kept for the next
//! lattice part that needs the same triangle.
//!
//! It deliberately knows nothing of how a net is rebuilt: the caller passes the rebuild, and the
//! memo only decides whether a kept copy can stand in for it. The rebuild is a pure function of
//! the surface's data, which does not change once the surface is built, so a kept copy has the
//! same bits as a fresh one and the output cannot depend on whether a lookup hits.
//!
//! Why: the tessellator evaluates a welded edge's samples once, from its lowest-numbered
//! triangle, and that needs the neighbour's net as well (Eq. 3 re-expresses it across the
//! edge). At level 2 every evaluated point is an edge's midpoint, so each triangle's net was
//! rebuilt once for its own edges and once more for every neighbour that evaluates a shared
//! edge: about 2.5 rebuilds per triangle on a closed mesh, at about 600 instructions each (the
//! corner normals normalized, seven points put back together and six of them projected into
//! their tangent planes). The neighbour across an edge a triangle evaluates always comes later
//! in triangle order (the evaluator is the edge's lowest-numbered triangle), and in meshes made
//! or stored in any spatial order it comes soon after: on the bench icospheres 99.6% (1M) and
//! 98.6% (100k) of neighbours lie within [`SLOTS`] triangles of each other. A direct-mapped
//! table of that many entries per thread therefore keeps almost every net from its first
//! rebuild to its last use, in 336 KiB that stay in the core's L2 cache.

use std::cell::RefCell;
use std::sync::atomic::{AtomicU64, Ordering};

use glam::DVec3;

use super::neighbour_net::SoaNet;

/// One triangle's whole net and corner normals, put together for a lattice part or a point.
#[derive(Debug, Clone, Copy, PartialEq)]
pub(super) struct Local {
    pub net: SoaNet,
    pub normal: [DVec3; 3],
}

/// Entries per thread, a power of two: triangle `t` is kept in slot `t mod SLOTS`.
pub(super) const SLOTS: usize = 1024;
const _: () = assert!(SLOTS.is_power_of_two());

/// One kept net, tagged with the surface and the triangle it belongs to.
#[derive(Clone, Copy)]
struct Slot {
    owner: u64,
    tri: u32,
    local: Local,
}

/// Owner of no surface: the tag of an empty slot.
const NOBODY: u64 = 0;

const EMPTY: Slot = Slot {
    owner: NOBODY,
    tri: 0,
    local: Local {
        net: [[0.0; 10]; 3],
        normal: [DVec3::ZERO; 3],
    },
};

thread_local! {
    /// Allocated on a thread's first lookup, then reused by every surface.
    static MEMO: RefCell<Option<Box<[Slot; SLOTS]>>> = const { RefCell::new(None) };
}

/// A tag no other surface of this process has had: a surface takes one when it is built, so
/// that a slot left by a surface that is gone (whose memory a new one may reuse) never matches.
pub(super) fn new_owner() -> u64 {
    static NEXT: AtomicU64 = AtomicU64::new(NOBODY + 1);
    NEXT.fetch_add(1, Ordering::Relaxed)
}

/// `read` of triangle `tri`'s net for the surface tagged `owner`: the kept copy if this thread
/// has one, else the net `rebuild` writes, kept in place of whatever held its slot.
///
/// The net is read where it is kept and rebuilt in place: copying its 312 bytes in and out
/// cost a third as much as the rebuilds it saved.
#[inline]
pub(super) fn with_local<R>(
    owner: u64,
    tri: usize,
    rebuild: impl FnOnce(&mut Local),
    read: impl FnOnce(&Local) -> R,
) -> R {
    debug_assert_ne!(owner, NOBODY);
    let tag = tri as u32;
    let mut work = Some((rebuild, read));
    let kept = MEMO.try_with(|memo| {
        let mut memo = memo.borrow_mut();
        let slots = memo.get_or_insert_with(|| Box::new([EMPTY; SLOTS]));
        let slot = &mut slots[tri & (SLOTS - 1)];
        let (rebuild, read) = work.take().expect("taken once");
        if slot.owner != owner || slot.tri != tag {
            slot.owner = owner;
            slot.tri = tag;
            rebuild(&mut slot.local);
        }
        read(&slot.local)
    });
    match kept {
        Ok(value) => value,
        // Only while the thread is being torn down is there no memo: rebuild without keeping.
        Err(_) => {
            let (rebuild, read) = work.take().expect("not taken when the memo is gone");
            let mut local = EMPTY.local;
            rebuild(&mut local);
            read(&local)
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The net a lookup gave: `rebuild` writes `x`'s net.
    fn local(owner: u64, tri: usize, rebuild: impl FnOnce() -> Local) -> Local {
        with_local(owner, tri, |out| *out = rebuild(), |kept| *kept)
    }

    fn net(x: f64) -> Local {
        Local {
            net: [[x; 10]; 3],
            normal: [DVec3::splat(x); 3],
        }
    }

    #[test]
    fn a_kept_net_stands_in_only_for_its_own_surface_and_triangle() {
        let (a, b) = (new_owner(), new_owner());
        assert_ne!(a, b);
        assert_eq!(local(a, 5, || net(1.0)), net(1.0));
        // Kept: the rebuild is not run again.
        assert_eq!(local(a, 5, || unreachable!("kept")), net(1.0));
        // Same triangle of another surface: rebuilt, and then that one is kept.
        assert_eq!(local(b, 5, || net(2.0)), net(2.0));
        assert_eq!(local(b, 5, || unreachable!("kept")), net(2.0));
        // Another triangle in the same slot of the same surface: rebuilt.
        assert_eq!(local(b, 5 + SLOTS, || net(3.0)), net(3.0));
        assert_eq!(local(b, 5, || net(4.0)), net(4.0));
        // Triangles in other slots live side by side.
        assert_eq!(local(b, 6, || net(5.0)), net(5.0));
        assert_eq!(local(b, 5, || unreachable!("kept")), net(4.0));
    }

    #[test]
    fn each_thread_keeps_its_own_nets() {
        let owner = new_owner();
        assert_eq!(local(owner, 7, || net(1.0)), net(1.0));
        std::thread::spawn(move || {
            assert_eq!(local(owner, 7, || net(2.0)), net(2.0));
        })
        .join()
        .unwrap();
        assert_eq!(local(owner, 7, || unreachable!("kept")), net(1.0));
    }
}
