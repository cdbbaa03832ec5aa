//! Secrets the daemon hands out: its instance id, scene ids, scene tokens and frame keys,
//! drawn from the operating system's random source (`getrandom`), so no client can guess
//! or predict them (DESIGN §10).

/// A random `u64` from the operating system, never 0 (0 means "none" on the wire).
///
/// # Errors
/// The operating system's random source failed (it never does on a working Linux).
pub fn random_u64() -> Result<u64, getrandom::Error> {
    loop {
        let value = getrandom::u64()?;
        if value != 0 {
            return Ok(value);
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn draws_differ_and_are_never_zero() {
        let draws: Vec<u64> = (0..64).map(|_| random_u64().unwrap()).collect();
        assert!(draws.iter().all(|&v| v != 0));
        let mut sorted = draws.clone();
        sorted.sort_unstable();
        sorted.dedup();
        assert_eq!(sorted.len(), draws.len(), "64 draws of 64 bits repeat");
    }
}
