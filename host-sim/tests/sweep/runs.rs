//! Layouts and seeds; the same results on 1 and 2 threads; 3 shards + merge = one run;
//! common seeds; stopping keeps what finished.

use super::*;

#[test]
fn grid_and_random_layouts() {
    let p = plan(TINY).unwrap();
    let cells: Vec<String> = p
        .points
        .iter()
        .map(|q| format!("{}/{}", q[0], q[1]))
        .collect();
    assert_eq!(
        cells,
        ["0.1/0.0", "0.1/0.3", "0.4/0.0", "0.4/0.3"],
        "first axis slowest"
    );
    assert_eq!(p.jobs(), 12);
    assert_eq!(p.job(7), (2, 1));
    let random = "sampling = \"random\"\npoints = 50\nseed = 3\n[base]\nscenario = \"paper\"\n\
                  [[axes]]\nkey = \"radio.loss\"\nfrom = 0.1\nto = 0.2\n\
                  [[axes]]\nkey = \"mode\"\nvalues = [\"sampled\", \"continuous\"]\n";
    let r1 = plan(random).unwrap();
    let r2 = plan(random).unwrap();
    assert_eq!(r1.points, r2.points, "the same seed draws the same points");
    let losses: Vec<f64> = r1.points.iter().map(|q| q[0].as_float().unwrap()).collect();
    assert!(losses.iter().all(|x| (0.1..=0.2).contains(x)));
    assert!(losses.windows(2).any(|w| w[0] != w[1]));
    assert!(r1
        .points
        .iter()
        .any(|q| q[1].as_str() == Some("continuous")));
    assert!(r1.points.iter().any(|q| q[1].as_str() == Some("sampled")));
    // Seeds: fixed by (sweep seed, point, run), below 2^63, all different here.
    let seeds: Vec<u64> = (0..4)
        .flat_map(|p| (0..3).map(move |r| run_seed(7, p, r)))
        .collect();
    assert!(seeds.iter().all(|&s| s < 1 << 63));
    let mut unique = seeds.clone();
    unique.sort_unstable();
    unique.dedup();
    assert_eq!(unique.len(), seeds.len());
    assert_eq!(run_seed(7, 2, 1), run_seed(7, 2, 1));
    assert_ne!(run_seed(7, 2, 1), run_seed(8, 2, 1));
}

// ---------------------------------------------------------------- determinism, shards

#[test]
fn same_results_on_one_and_two_threads() {
    let p = plan(TINY).unwrap();
    let one = run_in_pool(&p, 1, Shard::ALL);
    let two = run_in_pool(&p, 2, Shard::ALL);
    assert!(!one.interrupted && one.rows.len() == 12);
    let order: Vec<(usize, u64)> = two.rows.iter().map(|r| (r.point, r.run)).collect();
    let want: Vec<(usize, u64)> = (0..12).map(|j| p.job(j)).collect();
    assert_eq!(order, want, "rows in job order");
    let tmp = tempfile::tempdir().unwrap();
    let (d1, d2) = (tmp.path().join("one"), tmp.path().join("two"));
    write_all(&d1, &Manifest::new(&p, Shard::ALL, &one), &one.rows, false).unwrap();
    write_all(&d2, &Manifest::new(&p, Shard::ALL, &two), &two.rows, false).unwrap();
    for f in FILES {
        assert_eq!(
            read(&d1, f),
            read(&d2, f),
            "{f} differs between 1 and 2 threads"
        );
    }
    // The seeds matter: runs of one point differ (noise, loss, initial shape).
    let r = &one.rows;
    assert_ne!(r[0].v0, r[1].v0);
    assert!(
        r.iter()
            .all(|x| x.rotation_deg.is_some() && x.outcome != "error"),
        "{r:?}"
    );
}

#[test]
fn three_shards_merged_equal_one_run() {
    let p = plan(TINY).unwrap();
    let tmp = tempfile::tempdir().unwrap();
    let whole = run_in_pool(&p, 2, Shard::ALL);
    let all_dir = tmp.path().join("all");
    write_all(
        &all_dir,
        &Manifest::new(&p, Shard::ALL, &whole),
        &whole.rows,
        false,
    )
    .unwrap();
    let mut dirs = Vec::new();
    let mut total = 0;
    for k in [3, 1, 2] {
        let s = Shard { k, n: 3 };
        let done = run_in_pool(&p, 2, s);
        assert_eq!(done.jobs, 4);
        total += done.rows.len();
        let d = tmp.path().join(format!("shard{k}"));
        write_all(&d, &Manifest::new(&p, s, &done), &done.rows, false).unwrap();
        dirs.push(d);
    }
    assert_eq!(total, 12);
    let (m, rows) = merge(&dirs).unwrap();
    let merged = tmp.path().join("merged");
    write_all(&merged, &m, &rows, false).unwrap();
    for f in FILES {
        assert_eq!(
            read(&all_dir, f),
            read(&merged, f),
            "{f}: merge differs from one run"
        );
    }
    // A missing or repeated shard, or another sweep, is refused.
    let e = merge(&dirs[..2]).unwrap_err();
    assert!(
        e.reason.contains("2/3") && e.reason.contains("missing"),
        "{e}"
    );
    let e = merge(&[dirs[0].clone(), dirs[0].clone()]).unwrap_err();
    assert!(e.reason.contains("given twice"), "{e}");
    let other = plan(&TINY.replace("seed = 7", "seed = 8")).unwrap();
    let s = Shard { k: 2, n: 3 };
    let odd = tmp.path().join("other");
    let done = Default::default();
    write_all(&odd, &Manifest::new(&other, s, &done), &[], false).unwrap();
    let e = merge(&[dirs[0].clone(), odd]).unwrap_err();
    assert!(e.reason.contains("not a shard of the same sweep"), "{e}");
    assert!(merge(&[all_dir])
        .unwrap_err()
        .reason
        .contains("not a shard"));
}

#[test]
fn common_seeds_give_every_point_the_same_runs_seeds() {
    let p = plan(&TINY.replace("runs = 3", "runs = 2\ncommon_seeds = true")).unwrap();
    let done = run_in_pool(&p, 2, Shard::ALL);
    assert_eq!(done.rows.len(), 8);
    for r in &done.rows {
        assert_eq!(r.seed, run_seed(7, 0, r.run), "{r:?}");
    }
    // Points 0 and 2 differ only in the perturbation: the same rotation at both.
    assert_eq!(done.rows[0].rotation_deg, done.rows[4].rotation_deg);
    let own = plan(TINY).unwrap();
    assert_ne!(
        own.seed_of(1, 0),
        own.seed_of(0, 0),
        "by default each point has its own"
    );
}

#[test]
fn stopping_keeps_the_finished_runs() {
    let p = plan(TINY).unwrap();
    let pool = rayon::ThreadPoolBuilder::new()
        .num_threads(1)
        .build()
        .unwrap();
    let stop = AtomicBool::new(false);
    // Stop after the second finished run (as Ctrl-C would).
    let count = std::sync::atomic::AtomicUsize::new(0);
    let done = pool.install(|| {
        run_all(&p, Shard::ALL, &stop, &|_: &RunRow| {
            if count.fetch_add(1, Ordering::SeqCst) == 1 {
                stop.store(true, Ordering::SeqCst);
            }
        })
    });
    assert!(done.interrupted);
    assert_eq!(done.rows.len(), 2);
    let tmp = tempfile::tempdir().unwrap();
    let m = Manifest::new(&p, Shard::ALL, &done);
    write_all(tmp.path(), &m, &done.rows, false).unwrap();
    assert_eq!(
        read(tmp.path(), "runs.csv").lines().count(),
        3,
        "header + 2 runs"
    );
    let json: serde_json::Value = serde_json::from_str(&read(tmp.path(), "points.json")).unwrap();
    assert_eq!(json["interrupted"], true);
    assert_eq!(json["finished"], 2);
}
