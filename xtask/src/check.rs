//! Pass/fail bookkeeping of `firmware-check`.

use crate::budgets::Limit;

/// Counts passed checks and collects failures (each printed as it happens).
#[derive(Debug, Default)]
pub struct Checker {
    /// Checks that passed.
    pub passed: usize,
    /// Why each failed check failed.
    pub failures: Vec<String>,
    /// Where the budgets come from (named in failures).
    pub source: String,
}

impl Checker {
    /// A checker for budgets read from `source`.
    pub fn new(source: impl Into<String>) -> Self {
        Self {
            source: source.into(),
            ..Self::default()
        }
    }

    /// One more passed check.
    pub fn pass(&mut self) {
        self.passed += 1;
    }

    /// One failed check.
    pub fn fail(&mut self, why: impl Into<String>) {
        let why = why.into();
        eprintln!("FAIL: {why}");
        self.failures.push(why);
    }

    /// Passes if `ok`, else fails with `why`.
    pub fn expect(&mut self, ok: bool, why: impl FnOnce() -> String) {
        if ok {
            self.pass();
        } else {
            self.fail(why());
        }
    }

    /// Compares `value` with every budget in `limits` (one check each); returns the table
    /// cell: the tightest limit and `ok`, the first exceeded one and `OVER`, or `-`.
    pub fn budget(&mut self, what: &str, value: u64, limits: &[Limit]) -> String {
        let mut tightest: Option<u64> = None;
        for (key, limit) in limits {
            tightest = Some(tightest.map_or(*limit, |t| t.min(*limit)));
            if value > *limit {
                let source = self.source.clone();
                self.fail(format!(
                    "{what} = {value} exceeds budget {key} = {limit} ({source})"
                ));
                return format!("{limit} OVER");
            }
            self.pass();
        }
        tightest.map_or_else(|| "-".to_owned(), |t| format!("{t} ok"))
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn limits(v: &[(&str, u64)]) -> Vec<Limit> {
        v.iter().map(|(k, l)| ((*k).to_owned(), *l)).collect()
    }

    #[test]
    fn budget_cells_and_counts() {
        let mut c = Checker::new("b.toml");
        assert_eq!(c.budget("x", 5, &[]), "-");
        assert_eq!(c.budget("x", 5, &limits(&[("a", 10), ("b", 7)])), "7 ok");
        assert_eq!(c.passed, 2);
        assert_eq!(c.budget("x", 8, &limits(&[("a", 10), ("b", 7)])), "7 OVER");
        assert_eq!(c.passed, 3);
        assert_eq!(c.failures, ["x = 8 exceeds budget b = 7 (b.toml)"]);
        assert_eq!(
            c.budget("y", 11, &limits(&[("a", 10), ("b", 7)])),
            "10 OVER"
        );
        assert_eq!(c.failures.len(), 2);
        c.expect(true, || unreachable!());
        c.expect(false, || "z".into());
        assert_eq!((c.passed, c.failures.len()), (4, 3));
    }
}
