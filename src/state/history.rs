//! A contact's history: what a contact law carries from one step to the next for a pair in
//! contact (for every law today, the elastic tangential displacement ξ). The solver stores,
//! re-orders, saves, hashes and restores it without knowing what it holds.

use crate::Vec3;

/// The per-contact state of a contact law. A new contact starts from `Default` (no history).
pub trait History: Copy + Default + PartialEq + std::fmt::Debug + Send + Sync + 'static {
    /// Number of f64 words of its canonical form (state hash and checkpoint).
    const WORDS: usize;
    /// Appends its canonical words, in a fixed order, to `out`.
    fn put_words(&self, out: &mut Vec<f64>);
    /// The history of canonical words `words` (`WORDS` of them, as `put_words` wrote them).
    fn from_words(words: &[f64]) -> Self;
    /// The elastic tangential displacement (length) that MercuryCG's `.fstat` reports as the
    /// tangential overlap (its length, negated); zero for a history without a tangential spring.
    fn spring(&self) -> Vec3;
}

/// The elastic tangential displacement ξ (length) of the spring-dashpot-slider laws; canonical
/// words ξx, ξy, ξz.
impl History for Vec3 {
    const WORDS: usize = 3;

    fn put_words(&self, out: &mut Vec<f64>) {
        out.extend_from_slice(&[self.x, self.y, self.z]);
    }

    fn from_words(words: &[f64]) -> Self {
        Vec3::new(words[0], words[1], words[2])
    }

    fn spring(&self) -> Vec3 {
        *self
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_spring_round_trips_through_its_words() {
        let xi = Vec3::new(1e-3, -2.5e-17, f64::MIN_POSITIVE);
        let mut words = Vec::new();
        xi.put_words(&mut words);
        assert_eq!(words.len(), <Vec3 as History>::WORDS);
        let back = <Vec3 as History>::from_words(&words);
        assert_eq!(back.map(f64::to_bits), xi.map(f64::to_bits));
        assert_eq!(back.spring(), xi);
    }
}
