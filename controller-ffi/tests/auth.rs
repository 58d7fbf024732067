//! `PH_INTEGRITY_AUTH` through the C API: the key in `ph_config` and in the blob, exact
//! round trips, refusal of a key with another integrity, the boot epoch, and the new
//! frame statuses and counters.

mod fixture;

use ph_formation_core::{Integrity, SwarmKey};
use ph_formation_ffi::api::{
    ph_agent_init, ph_agent_set_boot_epoch, ph_frames, ph_receive, ph_stats,
};
use ph_formation_ffi::config::{from_core, ph_integrity};
use ph_formation_ffi::storage::ph_agent;
use ph_formation_ffi::tick::ph_frame_stats;
use ph_formation_ffi::{decode_blob, encode_blob, ph_config, ph_status, to_core, PH_AGENT_SIZE};

const KEY: [u8; 16] = *b"ffi swarm key 16";

/// Agent `id` of triangle (1, 2, 3) with angles at 1 and 2 (60° each), `auth`.
fn config(id: u8) -> ph_config {
    let mut c = fixture::triangle_config(id);
    c.integrity = ph_integrity::PH_INTEGRITY_AUTH as u8;
    c.auth_key = KEY;
    c
}

#[test]
fn the_key_round_trips_through_the_c_form_and_the_blob() {
    let c = config(3);
    let core = to_core(&c).expect("valid");
    assert_eq!(core.integrity, Integrity::Auth(SwarmKey::new(KEY)));
    assert_eq!(to_core(&from_core(&core)), Ok(core.clone()));
    let mut blob = [0u8; 1024];
    let n = encode_blob(&core, &mut blob).expect("encodes");
    assert_eq!(decode_blob(&blob[..n]).expect("decodes"), core);
    // A key with another integrity is refused (the C form must stay exact).
    let mut crc = config(3);
    crc.integrity = ph_integrity::PH_INTEGRITY_CRC16 as u8;
    assert_eq!(to_core(&crc), Err(ph_status::PH_ERR_CONFIG_BAD_ENUM));
    crc.auth_key = [0; 16];
    assert_eq!(to_core(&crc).map(|c| c.integrity), Ok(Integrity::Crc16));
}

use fixture::Memory;

fn init(mem: &mut Memory, c: &ph_config) -> *mut ph_agent {
    let a = mem.0.as_mut_ptr().cast::<ph_agent>();
    // SAFETY: `mem` is PH_AGENT_SIZE bytes, 8-aligned, and outlives the agent's use.
    assert_eq!(
        unsafe { ph_agent_init(a, PH_AGENT_SIZE, c) },
        ph_status::PH_OK
    );
    a
}

#[test]
fn frames_are_signed_and_forgeries_and_replays_get_their_status() {
    let (mut m1, mut m3) = (Memory([0; PH_AGENT_SIZE]), Memory([0; PH_AGENT_SIZE]));
    let tx = init(&mut m1, &config(1));
    let rx = init(&mut m3, &config(3));
    let mut frames = [[0u8; 60]; 3];
    let mut lens = [0u8; 3];
    let mut count = 0usize;
    // SAFETY: valid agents and buffers of the stated sizes.
    unsafe {
        assert_eq!(ph_agent_set_boot_epoch(tx, 9), ph_status::PH_OK);
        assert_eq!(
            ph_frames(tx, frames.as_mut_ptr(), lens.as_mut_ptr(), 3, &mut count),
            ph_status::PH_OK
        );
        assert_eq!(count, 1);
        let f = &frames[0][..usize::from(lens[0])];
        let mut forged = f.to_vec();
        forged[5] ^= 1;
        assert_eq!(
            ph_receive(rx, forged.as_ptr(), forged.len()),
            ph_status::PH_ERR_FRAME_BAD_TAG
        );
        assert_eq!(ph_receive(rx, f.as_ptr(), f.len()), ph_status::PH_OK);
        assert_eq!(
            ph_receive(rx, f.as_ptr(), f.len()),
            ph_status::PH_ERR_FRAME_REPLAYED
        );
        let mut s = ph_frame_stats::default();
        assert_eq!(ph_stats(rx, &mut s), ph_status::PH_OK);
        assert_eq!(
            (s.accepted, s.bad_tag, s.replayed, s.unsynced),
            (1, 1, 1, 0)
        );
    }
}
