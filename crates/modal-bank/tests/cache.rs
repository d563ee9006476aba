//! Bank cache and cache keys.

mod common;

use common::linear_bank;
use modal_bank::{default_dir_from, retune, BankCache, BankError, CacheKey, ModeBank, RetuneSpec};
use std::path::PathBuf;

fn key(seed: u64) -> String {
    CacheKey::new("modal-bank-v1").add_u64("seed", seed).finish()
}

fn bank_for(key: &str) -> ModeBank {
    let mut bank = linear_bank(3);
    bank.info.input_hash = key.into();
    bank
}

#[test]
fn cache_key_matches_the_documented_encoding() {
    // Expected value from an independent Python implementation of the
    // encoding in src/key.rs (hashlib.sha256 + struct.pack('<Q'/'<d')).
    let k = CacheKey::new("modal-bank-v1")
        .add("mesh", b"abc")
        .add_str("material", "steel")
        .add_u64("order", 2)
        .add_f64("youngs_pa", 2e11)
        .add_f64s("fix_box", &[0.0, 1.5])
        .finish();
    assert_eq!(k, "2ae083ef0428b04490bf20fc451dcdfe9305a9fa0293acab0fc103d76c0846b1");
}

#[test]
fn cache_key_fields_cannot_collide_by_concatenation() {
    let base = || CacheKey::new("d");
    let keys = [
        base().add("a", b"bc").finish(),
        base().add("ab", b"c").finish(),
        base().add("a", b"b").add("", b"c").finish(),
        base().add_str("a", "bc").finish(),
        base().add_u64("x", 1).finish(),
        base().add_f64("x", 1.0).finish(),
        base().add_f64s("x", &[1.0]).finish(),
        base().add_f64("x", 0.1).finish(),
        base().add_f64("x", 0.1 + 1e-17 * 2.0).finish(), // next float up
        CacheKey::new("e").add("a", b"bc").finish(),
    ];
    for i in 0..keys.len() {
        for j in 0..i {
            assert_ne!(keys[i], keys[j], "keys {i} and {j} collide");
        }
    }
    assert_eq!(base().add("a", b"bc").finish(), keys[0], "deterministic");
}

#[test]
fn miss_put_hit_remove() {
    let dir = tempfile::tempdir().unwrap();
    let cache = BankCache::new(dir.path().join("not/yet/there"));
    let k = key(1);
    assert!(cache.get(&k).unwrap().is_none(), "miss in a missing directory");
    let bank = bank_for(&k);
    cache.put(&k, &bank).unwrap();
    assert_eq!(cache.get(&k).unwrap(), Some(bank));
    assert!(cache.get(&key(2)).unwrap().is_none());
    assert!(cache.remove(&k).unwrap());
    assert!(!cache.remove(&k).unwrap());
    assert!(cache.get(&k).unwrap().is_none());
}

#[test]
fn corrupted_entry_is_reported_not_served_and_can_be_replaced() {
    let dir = tempfile::tempdir().unwrap();
    let cache = BankCache::new(dir.path());
    let k = key(3);
    let bank = bank_for(&k);
    cache.put(&k, &bank).unwrap();
    let path = cache.path_for(&k).unwrap();
    let mut bytes = std::fs::read(&path).unwrap();
    let last = bytes.len() - 1;
    bytes[last] ^= 0x40;
    std::fs::write(&path, &bytes).unwrap();
    let err = cache.get(&k).unwrap_err();
    assert!(err.is_corrupt_cache_entry(), "{err}");
    assert!(err.to_string().contains("checksum mismatch"), "{err}");
    std::fs::write(&path, &bytes[..bytes.len() / 2]).unwrap();
    let err = cache.get(&k).unwrap_err();
    assert!(
        matches!(&err, BankError::CorruptCacheEntry { reason, .. } if matches!(**reason, BankError::Truncated { .. }))
    );
    cache.put(&k, &bank).unwrap();
    assert_eq!(cache.get(&k).unwrap(), Some(bank));
}

#[test]
fn entry_under_the_wrong_key_is_corrupt() {
    let dir = tempfile::tempdir().unwrap();
    let cache = BankCache::new(dir.path());
    let (a, b) = (key(4), key(5));
    cache.put(&a, &bank_for(&a)).unwrap();
    std::fs::copy(cache.path_for(&a).unwrap(), cache.path_for(&b).unwrap()).unwrap();
    let err = cache.get(&b).unwrap_err();
    assert!(
        matches!(&err, BankError::CorruptCacheEntry { reason, .. } if matches!(**reason, BankError::KeyMismatch { .. }))
    );
}

#[test]
fn put_refuses_mismatched_hash_and_retuned_banks() {
    let dir = tempfile::tempdir().unwrap();
    let cache = BankCache::new(dir.path());
    let k = key(6);
    let err = cache.put(&key(7), &bank_for(&k)).unwrap_err();
    assert!(matches!(err, BankError::KeyMismatch { .. }), "{err}");
    // A retuned bank carries "retuned:<hex>", which is not a valid key, and no
    // valid key equals it: it can never be stored or served as a fresh solve.
    let retuned = retune(&bank_for(&k), RetuneSpec { scale: Some(2.0), ..Default::default() }).unwrap();
    assert!(cache.put(&retuned.info.input_hash, &retuned).is_err());
    assert!(matches!(cache.put(&k, &retuned), Err(BankError::KeyMismatch { .. })));
    assert!(cache.get(&k).unwrap().is_none());
}

#[test]
fn invalid_keys_are_rejected() {
    let cache = BankCache::new("/nonexistent");
    for bad in ["", "abc", &"A".repeat(64), &"g".repeat(64), "../../../../etc/passwd", &"a".repeat(65)] {
        assert!(matches!(cache.get(bad), Err(BankError::InvalidCacheKey(_))), "{bad}");
    }
}

#[test]
fn concurrent_writers_of_one_key_leave_one_complete_entry() {
    let dir = tempfile::tempdir().unwrap();
    let cache = BankCache::new(dir.path());
    let k = key(8);
    let bank = bank_for(&k);
    std::thread::scope(|s| {
        for _ in 0..8 {
            s.spawn(|| {
                for _ in 0..5 {
                    cache.put(&k, &bank).unwrap();
                    // Readers never see a partial file.
                    assert_eq!(cache.get(&k).unwrap().as_ref(), Some(&bank));
                }
            });
        }
    });
    let names: Vec<_> = std::fs::read_dir(dir.path()).unwrap().map(|e| e.unwrap().file_name()).collect();
    assert_eq!(names, vec![std::ffi::OsString::from(format!("{k}.bank"))], "no temporary files left");
}

#[test]
fn default_dir_precedence() {
    let os = |s: &str| Some(std::ffi::OsString::from(s));
    assert_eq!(default_dir_from(os("/m"), os("/x"), os("/h")).unwrap(), PathBuf::from("/m"));
    assert_eq!(default_dir_from(None, os("/x"), os("/h")).unwrap(), PathBuf::from("/x/modal"));
    assert_eq!(default_dir_from(os(""), os(""), os("/h")).unwrap(), PathBuf::from("/h/.cache/modal"));
    assert_eq!(default_dir_from(None, os("relative"), os("/h")).unwrap(), PathBuf::from("/h/.cache/modal"));
    assert!(matches!(default_dir_from(None, None, None), Err(BankError::NoCacheDir)));
}

#[test]
fn deferred_entries_give_the_light_bank_first_and_the_same_bank_or_error_at_the_end() {
    let dir = tempfile::tempdir().unwrap();
    let cache = BankCache::new(dir.path());
    let k = key(6);
    assert!(cache.get_deferred(&k).unwrap().is_none());
    let bank = bank_for(&k);
    cache.put(&k, &bank).unwrap();
    let (light, rest) = cache.get_deferred(&k).unwrap().unwrap();
    assert!(light.shapes.is_empty());
    assert_eq!(ModeBank { shapes: bank.shapes.clone(), ..light }, bank);
    assert_eq!(rest.finish().unwrap(), bank);

    // A flipped bit inside the data passes step 1 and is caught by step 2.
    let path = cache.path_for(&k).unwrap();
    let mut bytes = std::fs::read(&path).unwrap();
    let last = bytes.len() - 1;
    bytes[last] ^= 0x40;
    std::fs::write(&path, &bytes).unwrap();
    let (_, rest) = cache.get_deferred(&k).unwrap().unwrap();
    let err = rest.finish().unwrap_err();
    assert!(err.is_corrupt_cache_entry() && err.to_string().contains("checksum mismatch"), "{err}");
    // A truncated entry or one filed under another key fails at step 1.
    std::fs::write(&path, &bytes[..bytes.len() / 2]).unwrap();
    assert!(cache.get_deferred(&k).unwrap_err().is_corrupt_cache_entry());
    let other = key(7);
    cache.put(&k, &bank).unwrap();
    std::fs::copy(&path, cache.path_for(&other).unwrap()).unwrap();
    let err = cache.get_deferred(&other).unwrap_err();
    assert!(
        matches!(&err, BankError::CorruptCacheEntry { reason, .. } if matches!(**reason, BankError::KeyMismatch { .. }))
    );
}
