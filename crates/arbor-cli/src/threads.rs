//! `--threads N` of `render` and `bench`: 0 (the default) uses every core; more than four threads per
//! core is refused as a usage error (exit 2) before anything starts, because a CPU-bound renderer gains
//! nothing from them and thousands of threads take minutes to start and can exhaust the address space.

use clap::Args;

use crate::Failure;

/// Threads allowed per core.
const PER_CORE: usize = 4;

/// The `--threads` flag.
#[derive(Args, Clone, Copy, Debug)]
pub struct ThreadsArg {
    /// Worker threads; 0 uses all cores. At most 4 per core.
    #[arg(long = "threads", value_name = "N", default_value_t = 0, value_parser = parse_threads)]
    pub n: usize,
}

impl ThreadsArg {
    /// Sets up the global thread pool: `N` threads, or one per core for 0.
    pub fn apply(self) -> Result<(), Failure> {
        if self.n == 0 {
            return Ok(());
        }
        rayon::ThreadPoolBuilder::new()
            .num_threads(self.n)
            .build_global()
            .map_err(|e| arbor::Error::Invalid(format!("cannot start {} threads: {e}", self.n)).into())
    }

    /// The number of threads work runs on once [`apply`](Self::apply) was called.
    pub fn count(self) -> usize {
        if self.n == 0 {
            rayon::current_num_threads()
        } else {
            self.n
        }
    }
}

/// The cores of this machine (1 when the system does not say).
fn cores() -> usize {
    std::thread::available_parallelism().map_or(1, |n| n.get())
}

/// Parses `--threads`: a whole number from 0 to 4 per core.
pub fn parse_threads(s: &str) -> Result<usize, String> {
    let n: usize = s.trim().parse().map_err(|_| format!("'{s}' is not a whole number"))?;
    check(n, cores())
}

fn check(n: usize, cores: usize) -> Result<usize, String> {
    let max = PER_CORE * cores;
    if n > max {
        return Err(format!(
            "at most {max} threads ({PER_CORE} per core on this machine of {cores}); 0 uses all cores"
        ));
    }
    Ok(n)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn threads_bound_is_four_per_core() {
        assert_eq!(check(0, 2), Ok(0));
        assert_eq!(check(8, 2), Ok(8));
        assert_eq!(check(9, 2), Err("at most 8 threads (4 per core on this machine of 2); 0 uses all cores".into()));
        assert_eq!(parse_threads("x"), Err("'x' is not a whole number".into()));
        assert_eq!(parse_threads("-1"), Err("'-1' is not a whole number".into()));
    }
}
