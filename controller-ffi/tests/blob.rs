//! The configuration blob: round trip, every refusal with its own status, the CRC, the
//! size bound, and the pinned bytes of one blob (a change of the core's configuration
//! layout must come with a new `BLOB_VERSION`).

use ph_formation_core::{
    AgentConfig, AngleConfig, EstimatorMode, LeaderConfig, LeaderRole, Schedule, ScheduleStep,
    TriangleConfig, MAX_SCHEDULE_STEPS,
};
use ph_formation_ffi::api::ph_agent_init_blob;
use ph_formation_ffi::blob::{BLOB_VERSION, PH_MAX_BLOB_LEN};
use ph_formation_ffi::policy::{ph_blob_policy, ph_policy_config};
use ph_formation_ffi::storage::ph_agent;
use ph_formation_ffi::{
    decode_blob, decode_blob_policy, encode_blob, encode_blob_with, ph_status, BlobError,
    BlobPolicy, FfiConfig, PH_AGENT_SIZE,
};

/// Agent 1 of the paper's formation (firmware-example/src/paper.rs).
fn paper_agent_1() -> FfiConfig {
    let angle = |apex, cos_desired| AngleConfig {
        apex,
        cos_desired,
        stiffness: 1000.0,
        damping: 10.0,
        estimator_gain: 1000.0,
    };
    let mut c = AgentConfig::new(1);
    c.friction = [0.5; 2];
    c.velocity_damping = [1.8; 2];
    c.velocity_reference = Schedule::constant([3.0, 3.0]);
    c.limits.max_force = 1e5;
    c.triangles
        .push(TriangleConfig {
            vertices: [1, 2, 3],
            angles: [angle(1, 0.0), angle(3, core::f32::consts::FRAC_1_SQRT_2)],
        })
        .expect("capacity");
    c.leader = Some(LeaderConfig {
        role: LeaderRole::A,
        partner: 2,
        stiffness: 1.0,
        damping: [0.8; 2],
        displacement: Schedule::constant([10.0, -10.0]),
    });
    c
}

/// Every capacity used: 8 triangles, 12 neighbours (11 in triangles and the leader
/// partner), full schedules.
fn largest() -> FfiConfig {
    let mut c = paper_agent_1();
    c.estimator = EstimatorMode::PerAgent;
    c.triangles.clear();
    for k in 0..8u8 {
        let (v, w) = (10 + (2 * k) % 11, 10 + (2 * k + 1) % 11);
        let a = |apex| AngleConfig {
            apex,
            cos_desired: 0.5,
            stiffness: 1.0,
            damping: 1.0,
            estimator_gain: 1.0,
        };
        c.triangles
            .push(TriangleConfig {
                vertices: [1, v, w],
                angles: [a(v), a(w)],
            })
            .expect("capacity");
    }
    let full = || {
        let mut s = Schedule::default();
        for k in 0..MAX_SCHEDULE_STEPS {
            s.steps
                .push(ScheduleStep {
                    from: k as f32 * 1.5e7,
                    value: [-1.5e30, 2.5e-30],
                })
                .expect("capacity");
        }
        s
    };
    c.velocity_reference = full();
    if let Some(l) = c.leader.as_mut() {
        l.partner = 200;
        l.displacement = full();
    }
    c
}

fn encode(c: &FfiConfig) -> Vec<u8> {
    let mut buf = [0u8; PH_MAX_BLOB_LEN];
    let n = encode_blob(c, &mut buf).expect("encode");
    buf[..n].to_vec()
}

/// CRC-32/ISO-HDLC, bit by bit (the test's own oracle).
fn crc32(bytes: &[u8]) -> u32 {
    let mut crc = !0u32;
    for &b in bytes {
        crc ^= u32::from(b);
        for _ in 0..8 {
            crc = if crc & 1 != 0 {
                (crc >> 1) ^ 0xEDB8_8320
            } else {
                crc >> 1
            };
        }
    }
    !crc
}

/// Builds an agent from `blob` through the C entry point.
fn init_blob(blob: &[u8]) -> ph_status {
    #[repr(C, align(8))]
    struct Memory([u8; PH_AGENT_SIZE]);
    let mut mem = Box::new(Memory([0; PH_AGENT_SIZE]));
    let agent = mem.0.as_mut_ptr().cast::<ph_agent>();
    // SAFETY: `mem` is PH_AGENT_SIZE writable bytes aligned to 8; `blob` is readable.
    unsafe { ph_agent_init_blob(agent, PH_AGENT_SIZE, blob.as_ptr(), blob.len()) }
}

#[test]
fn round_trip() {
    for c in [paper_agent_1(), largest()] {
        let blob = encode(&c);
        assert_eq!(decode_blob(&blob), Ok(c));
        assert_eq!(init_blob(&blob), ph_status::PH_OK);
    }
}

#[test]
fn layout_header_and_crc32() {
    let blob = encode(&paper_agent_1());
    assert_eq!(&blob[..4], b"PHCF");
    assert_eq!(blob[4], BLOB_VERSION);
    assert_eq!(blob[5], 0);
    let n = usize::from(u16::from_le_bytes([blob[6], blob[7]]));
    assert_eq!(blob.len(), 8 + n + 4);
    let (body, check) = blob.split_at(8 + n);
    assert_eq!(crc32(body).to_le_bytes(), check);
    assert_eq!(crc32(b"123456789"), 0xCBF4_3926); // the catalogue's check value
}

#[test]
fn the_largest_configuration_fits() {
    let blob = encode(&largest());
    println!(
        "largest blob: {} bytes (bound {PH_MAX_BLOB_LEN})",
        blob.len()
    );
    assert!(blob.len() <= PH_MAX_BLOB_LEN);
    let mut small = vec![0u8; blob.len() - 1];
    assert_eq!(
        encode_blob(&largest(), &mut small),
        Err(BlobError::BufferTooSmall)
    );
    assert_eq!(
        encode_blob(&largest(), &mut [0u8; 4]),
        Err(BlobError::BufferTooSmall)
    );
}

#[test]
fn every_defect_has_its_status() {
    let good = encode(&paper_agent_1());
    let fix_crc = |b: &mut Vec<u8>| {
        let n = b.len() - 4;
        let c = crc32(&b[..n]);
        b[n..].copy_from_slice(&c.to_le_bytes());
    };
    let mut cases: Vec<(&str, Vec<u8>, ph_status)> = Vec::new();
    let mut b = good.clone();
    b[0] = b'X';
    cases.push(("magic", b, ph_status::PH_ERR_BLOB_MAGIC));
    let mut b = good.clone();
    b[4] = BLOB_VERSION + 1;
    fix_crc(&mut b);
    cases.push(("version", b, ph_status::PH_ERR_BLOB_VERSION));
    let mut b = good.clone();
    b[5] = 1;
    fix_crc(&mut b);
    cases.push(("reserved byte", b, ph_status::PH_ERR_BLOB_VERSION));
    cases.push((
        "truncated",
        good[..good.len() - 1].to_vec(),
        ph_status::PH_ERR_BLOB_LENGTH,
    ));
    cases.push((
        "header only",
        good[..8].to_vec(),
        ph_status::PH_ERR_BLOB_LENGTH,
    ));
    cases.push(("5 bytes", good[..5].to_vec(), ph_status::PH_ERR_BLOB_LENGTH));
    let mut b = good.clone();
    b.push(0);
    cases.push(("one byte more", b, ph_status::PH_ERR_BLOB_LENGTH));
    let mut b = good.clone();
    b[10] ^= 0x40;
    cases.push(("flipped payload bit", b, ph_status::PH_ERR_BLOB_CHECKSUM));
    let mut b = good.clone();
    let last = b.len() - 1;
    b[last] ^= 1;
    cases.push(("flipped CRC bit", b, ph_status::PH_ERR_BLOB_CHECKSUM));
    // Payload that is not a configuration, with a correct CRC.
    let mut b = good[..8].to_vec();
    b.extend_from_slice(&[0xFF; 5]);
    b[6..8].copy_from_slice(&5u16.to_le_bytes());
    b.extend_from_slice(&[0; 4]);
    fix_crc(&mut b);
    cases.push(("garbage payload", b, ph_status::PH_ERR_BLOB_DECODE));
    // A valid configuration followed by a stray byte inside the payload.
    let mut b = good[..good.len() - 4].to_vec();
    b.push(0);
    let n = u16::try_from(b.len() - 8).expect("small");
    b[6..8].copy_from_slice(&n.to_le_bytes());
    b.extend_from_slice(&[0; 4]);
    fix_crc(&mut b);
    cases.push(("trailing payload byte", b, ph_status::PH_ERR_BLOB_DECODE));
    // Well-formed, but a configuration the core refuses (written without encode_blob's
    // check): agent 1 in a triangle without agent 1.
    let mut bad = paper_agent_1();
    bad.triangles[0].vertices = [2, 3, 4];
    let mut payload = postcard::to_allocvec(&bad).expect("postcard");
    payload.push(0); // no policy section (version 6)
    let mut b = good[..8].to_vec();
    b[6..8].copy_from_slice(&u16::try_from(payload.len()).expect("small").to_le_bytes());
    b.extend_from_slice(&payload);
    b.extend_from_slice(&[0; 4]);
    fix_crc(&mut b);
    cases.push((
        "refused configuration",
        b,
        ph_status::PH_ERR_CONFIG_NOT_IN_TRIANGLE,
    ));

    for (what, blob, want) in cases {
        assert_eq!(init_blob(&blob), want, "{what}");
    }
    assert_eq!(
        encode_blob(&bad, &mut [0u8; PH_MAX_BLOB_LEN]),
        Err(BlobError::Config(
            ph_formation_core::ConfigError::NotInTriangle { triangle: 0 }
        ))
    );
}

/// The bytes of agent 1's blob. When this fails because the core's `AgentConfig`
/// changed, old blobs no longer decode: bump `BLOB_VERSION` (src/blob.rs) and paste the
/// new bytes here.
#[test]
fn pinned_bytes_of_agent_1() {
    let hex: String = encode(&paper_agent_1())
        .iter()
        .map(|b| format!("{b:02x}"))
        .collect();
    let pinned = "50484346060096000101010203010000000000007a440000204100007a4403f304353f00007a440000204100007a44000000803fcdcccc3d0000003f0000003f6666e63f6666e63f010000000000004040000040400100020000803fcdcc4c3fcdcc4c3f010000000000002041000020c10050c347cdcccc3d0000803f6f12833a9e067f3f000000000135fa0e3d6f12033acdcc4c3d0000a0400001000049aa8f4e";
    assert_eq!(
        hex, pinned,
        "the blob layout changed: bump BLOB_VERSION and update the pinned bytes to\n{hex}"
    );
}

/// `ph_blob_policy` of a blob.
fn blob_policy(blob: &[u8]) -> (ph_status, ph_policy_config, [f32; 2], f32) {
    let mut c = ph_policy_config::default();
    let (mut start, mut tol) = ([f32::NAN; 2], f32::NAN);
    // SAFETY: `blob` is readable; the outputs are writable.
    let s = unsafe {
        ph_blob_policy(
            blob.as_ptr(),
            blob.len(),
            &mut c,
            start.as_mut_ptr(),
            &mut tol,
        )
    };
    (s, c, start, tol)
}

/// Version 6 carries the vehicle's safety policies and pre-flight reference: what
/// `encode_blob_with` wrote, `ph_blob_policy` reads back exactly; the agent still
/// initialises from the same blob; a blob without them gives `PH_ERR_BLOB_NO_POLICY`
/// (nothing written), a corrupted one its blob status, NULL outputs `PH_ERR_NULL`.
#[test]
fn the_policy_section_round_trips() {
    let policy = BlobPolicy {
        hold_timeout_ms: 2000,
        fence: Some(([-0.5, -0.5], [3.0, 3.0])),
        battery_land: 3.2,
        battery_ms: 2000,
        min_separation: 0.3,
        start: [0.45, 1.1],
        start_tolerance: 0.3,
    };
    let mut buf = [0u8; PH_MAX_BLOB_LEN];
    let n = encode_blob_with(&paper_agent_1(), Some(&policy), &mut buf).expect("encode");
    let blob = buf[..n].to_vec();
    let blob = blob.as_slice();
    assert_eq!(decode_blob_policy(blob), Ok(Some(policy)));
    assert_eq!(init_blob(blob), ph_status::PH_OK);
    let (s, c, start, tol) = blob_policy(blob);
    assert_eq!(s, ph_status::PH_OK);
    let want = ph_policy_config {
        hold_timeout_ms: 2000,
        fence: 1,
        fence_min: [-0.5, -0.5],
        fence_max: [3.0, 3.0],
        battery_land: 3.2,
        battery_ms: 2000,
        min_separation: 0.3,
    };
    assert_eq!((c, start, tol), (want, [0.45, 1.1], 0.3));
    // No fence: `fence = 0`.
    let open = BlobPolicy {
        fence: None,
        ..policy
    };
    let n = encode_blob_with(&paper_agent_1(), Some(&open), &mut buf).expect("encode");
    assert_eq!(blob_policy(&buf[..n]).1.fence, 0);
    // Without a policy section (negative control): refused, nothing written.
    let plain = encode(&paper_agent_1());
    let (s, c, start, _) = blob_policy(&plain);
    assert_eq!(s, ph_status::PH_ERR_BLOB_NO_POLICY);
    assert_eq!(c, ph_policy_config::default());
    assert!(start[0].is_nan());
    // A corrupted blob: its blob status.
    let mut bad = buf[..n].to_vec();
    bad[10] ^= 1;
    assert_eq!(blob_policy(&bad).0, ph_status::PH_ERR_BLOB_CHECKSUM);
    // NULL outputs.
    // SAFETY: `blob` is readable; NULL outputs are allowed.
    let s = unsafe {
        ph_blob_policy(
            blob.as_ptr(),
            blob.len(),
            std::ptr::null_mut(),
            std::ptr::null_mut(),
            std::ptr::null_mut(),
        )
    };
    assert_eq!(s, ph_status::PH_ERR_NULL);
}
