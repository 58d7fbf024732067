//! `ph_leader_partner`: the leader partner of an agent (what the Crazyflie app needs to
//! find the partner offset among its neighbours' positions), none for a follower.

mod fixture;

use ph_formation_ffi::api::{ph_agent_init, ph_leader_partner};
use ph_formation_ffi::storage::ph_agent;
use ph_formation_ffi::{ph_config, ph_status, PH_AGENT_SIZE};

use fixture::Memory;

/// Agent `id` of triangle (1, 2, 3); agents 1 and 2 are the leaders.
fn config(id: u8) -> ph_config {
    let mut c = fixture::triangle_config(id);
    if id <= 2 {
        c.has_leader = 1;
        c.leader.role = id - 1; // PH_LEADER_A, PH_LEADER_B
        c.leader.partner = 3 - id;
        c.leader.stiffness = 1.0;
        c.leader.damping = [0.5, 0.5];
        c.leader.displacement.count = 1;
        c.leader.displacement.steps[0].value = [1.0, 0.0];
    }
    c
}

fn partner(id: u8) -> (ph_status, u8, u8) {
    let mut mem = Memory([0; PH_AGENT_SIZE]);
    let a = mem.0.as_mut_ptr().cast::<ph_agent>();
    let (mut partner, mut is_leader) = (0xee, 0xee);
    // SAFETY: valid memory and out-pointers.
    unsafe {
        assert_eq!(
            ph_agent_init(a, PH_AGENT_SIZE, &config(id)),
            ph_status::PH_OK
        );
        let s = ph_leader_partner(a, &mut partner, &mut is_leader);
        (s, partner, is_leader)
    }
}

#[test]
fn leaders_name_their_partner_and_followers_none() {
    assert_eq!(partner(1), (ph_status::PH_OK, 2, 1));
    assert_eq!(partner(2), (ph_status::PH_OK, 1, 1));
    assert_eq!(partner(3), (ph_status::PH_OK, 0xee, 0));
    let mut p = 0;
    // SAFETY: NULL agent.
    let s = unsafe { ph_leader_partner(core::ptr::null(), &mut p, &mut p) };
    assert_eq!(s, ph_status::PH_ERR_NULL);
}
