//! A domain's shared-memory files in `/dev/shm`: which belong to exactly that domain, and
//! keeping them private to the user (mode 0600).

use std::os::unix::fs::PermissionsExt;
use std::path::PathBuf;

/// Where POSIX shared memory appears as files (Linux).
const SHM_DIR: &str = "/dev/shm";
/// Length of the hex SHA-1 iceoryx2 puts after the prefix of every dynamic storage's name.
const HASH_LEN: usize = 40;

/// Whether a `/dev/shm` file name belongs to domain `prefix`. iceoryx2 names every
/// shared-memory object `<prefix><40 hex digits: SHA-1 of the stored type>_<name><suffix>`, so
/// the prefix must be followed by exactly that: a name of domain `iso_a2_` starts with `iso_a`
/// too, but what follows `iso_a` there is `2_`, not 40 hex digits and `_`. (Prefixes are at most
/// 40 characters, so no other domain's name can put 40 hex digits and `_` right after `prefix`.)
pub(crate) fn belongs(prefix: &str, file_name: &str) -> bool {
    let Some(rest) = file_name.strip_prefix(prefix) else { return false };
    let rest = rest.as_bytes();
    rest.len() > HASH_LEN
        && rest[..HASH_LEN].iter().all(|b| b.is_ascii_digit() || (b'a'..=b'f').contains(b))
        && rest[HASH_LEN] == b'_'
}

/// The shared-memory files of domain `prefix` (and of no other), sorted.
pub fn domain_files(prefix: &str) -> Vec<PathBuf> {
    let mut files: Vec<PathBuf> = std::fs::read_dir(SHM_DIR)
        .into_iter()
        .flatten()
        .flatten()
        .filter(|e| belongs(prefix, &e.file_name().to_string_lossy()))
        .map(|e| e.path())
        .collect();
    files.sort();
    files
}

/// Makes every shared-memory file of the domain readable and writable by its owner only.
/// iceoryx2 creates its per-domain management segment (`…_node.<version>.global_mgmt`) for
/// every user (0666) and offers no setting for it; every other object it creates is 0600.
/// Another process of the same user opens the files as before.
pub(crate) fn make_private(prefix: &str) {
    for path in domain_files(prefix) {
        let Ok(meta) = std::fs::metadata(&path) else { continue };
        let mode = meta.permissions().mode();
        if mode & 0o077 != 0
            && let Err(e) = std::fs::set_permissions(&path, std::fs::Permissions::from_mode(mode & 0o600))
        {
            tracing::warn!(path = %path.display(), "cannot make a shared-memory file private: {e}");
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn only_the_exact_prefix_matches() {
        let hash = "9204dd183d1c4d8e1ff592a30766ffa6765aa8b5";
        assert!(belongs("iso_a", &format!("iso_a{hash}_node.0_10_0.global_mgmt")));
        assert!(belongs("iso_a2_", &format!("iso_a2_{hash}_1234.data")));
        assert!(!belongs("iso_a", &format!("iso_a2_{hash}_1234.data")), "another domain's");
        assert!(!belongs("iso_a", &format!("iso_a{}_1.data", &hash[..39])), "hash too short");
        assert!(!belongs("iso_a", &format!("iso_a{}_1.data", hash.to_uppercase())), "not iceoryx2's hex");
        assert!(!belongs("iso_a", "iso_a"));
        assert!(!belongs("iso_a", &format!("xiso_a{hash}_1.data")));
    }
}
