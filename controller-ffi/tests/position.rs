//! `ph_position_encode`, `ph_position_decode`, `ph_position_sender`: the core's
//! position packet (`ph_formation_core::wire::position`) with the agent's integrity mode;
//! under `auth` a spoofed or replayed packet is refused.

mod fixture;

use ph_formation_ffi::api::ph_agent_init;
use ph_formation_ffi::config::ph_integrity;
use ph_formation_ffi::position::{
    ph_position_decode, ph_position_encode, ph_position_peer, ph_position_sender,
    PH_MAX_POSITION_LEN,
};
use ph_formation_ffi::storage::ph_agent;
use ph_formation_ffi::{ph_config, ph_status, PH_AGENT_SIZE};

fn config(id: u8, auth: bool) -> ph_config {
    let mut c = fixture::triangle_config(id);
    if auth {
        c.integrity = ph_integrity::PH_INTEGRITY_AUTH as u8;
        c.auth_key = *b"position key 16b";
    }
    c
}

use fixture::Memory;

fn agent(mem: &mut Memory, c: &ph_config) -> *mut ph_agent {
    let a = mem.0.as_mut_ptr().cast::<ph_agent>();
    // SAFETY: PH_AGENT_SIZE bytes, 8-aligned, outliving the agent's use.
    assert_eq!(
        unsafe { ph_agent_init(a, PH_AGENT_SIZE, c) },
        ph_status::PH_OK
    );
    a
}

fn encode(a: *const ph_agent, q: [f32; 2], counter: u64) -> Vec<u8> {
    let mut out = [0u8; PH_MAX_POSITION_LEN];
    let mut len = 0usize;
    // SAFETY: valid agent and buffers.
    let s = unsafe {
        ph_position_encode(
            a,
            q.as_ptr(),
            counter,
            out.as_mut_ptr(),
            out.len(),
            &mut len,
        )
    };
    assert_eq!(s, ph_status::PH_OK);
    out[..len].to_vec()
}

fn decode(a: *const ph_agent, b: &[u8], peer: &mut ph_position_peer) -> (ph_status, u8, [f32; 2]) {
    let (mut sender, mut q) = (0u8, [0f32; 2]);
    // SAFETY: valid agent, bytes and outputs.
    let s =
        unsafe { ph_position_decode(a, b.as_ptr(), b.len(), peer, &mut sender, q.as_mut_ptr()) };
    (s, sender, q)
}

#[test]
fn crc16_round_trip_and_corruption() {
    let (mut m1, mut m2) = (Memory([0; PH_AGENT_SIZE]), Memory([0; PH_AGENT_SIZE]));
    let (tx, rx) = (
        agent(&mut m2, &config(2, false)),
        agent(&mut m1, &config(1, false)),
    );
    let b = encode(tx, [1.5, -2.0], 0);
    assert_eq!(b.len(), 13);
    let mut sender = 0u8;
    // SAFETY: valid bytes and output.
    assert_eq!(
        unsafe { ph_position_sender(b.as_ptr(), b.len(), &mut sender) },
        ph_status::PH_OK
    );
    assert_eq!(sender, 2);
    let mut peer = ph_position_peer::default();
    assert_eq!(
        decode(rx, &b, &mut peer),
        (ph_status::PH_OK, 2, [1.5, -2.0])
    );
    let mut bad = b.clone();
    bad[4] ^= 1;
    assert_eq!(
        decode(rx, &bad, &mut peer).0,
        ph_status::PH_ERR_FRAME_BAD_CRC
    );
}

#[test]
fn auth_refuses_spoofed_and_replayed_positions() {
    let (mut m1, mut m2) = (Memory([0; PH_AGENT_SIZE]), Memory([0; PH_AGENT_SIZE]));
    let (tx, rx) = (
        agent(&mut m2, &config(2, true)),
        agent(&mut m1, &config(1, true)),
    );
    let b = encode(tx, [0.5, 0.25], (7 << 32) | 1);
    assert_eq!(b.len(), 27);
    let mut peer = ph_position_peer::default();
    let mut spoof = b.clone();
    spoof[3] ^= 0x40;
    assert_eq!(
        decode(rx, &spoof, &mut peer).0,
        ph_status::PH_ERR_FRAME_BAD_TAG
    );
    assert_eq!(
        peer,
        ph_position_peer::default(),
        "a refusal records nothing"
    );
    assert_eq!(
        decode(rx, &b, &mut peer),
        (ph_status::PH_OK, 2, [0.5, 0.25])
    );
    assert_eq!(
        decode(rx, &b, &mut peer).0,
        ph_status::PH_ERR_FRAME_REPLAYED
    );
    // The next counter, and a new boot epoch's first, are taken.
    let next = encode(tx, [0.5, 0.3], (7 << 32) | 2);
    assert_eq!(decode(rx, &next, &mut peer).0, ph_status::PH_OK);
    let reboot = encode(tx, [0.5, 0.3], 8 << 32);
    assert_eq!(decode(rx, &reboot, &mut peer).0, ph_status::PH_OK);
    // A crc16 packet to an auth receiver: another mode.
    let mut m3 = Memory([0; PH_AGENT_SIZE]);
    let crc = encode(agent(&mut m3, &config(2, false)), [0.0, 0.0], 0);
    assert_eq!(
        decode(rx, &crc, &mut peer).0,
        ph_status::PH_ERR_FRAME_MODE_MISMATCH
    );
}
