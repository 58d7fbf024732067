//! Cross-crate tests of ph-formation that need the firmware under QEMU (`tests/*.rs`).
//! The core's own behaviour tests live with it, in `controller-core/tests/`.
