//! The usage example of README.md (kept equal to it by xtask's `package` tests).
use ph_formation_vehicle::crazyflie::Crazyflie;

fn main() {
    // A Crazyflie at rest at the origin, asked for 0.5 m/s along x for 2 s (no wind).
    let mut cf = Crazyflie::new([0.0, 0.0], [0.0, 0.0]);
    for _ in 0..200 {
        cf.step([0.5, 0.0], [0.0, 0.0], 0.01);
    }
    assert!((cf.v[0] - 0.5).abs() < 0.05, "velocity {:?}", cf.v);
    println!("q = {:?}, v = {:?}", cf.q, cf.v);
}
