//! Placeholder.

/// Placeholder.
#[derive(Debug, Clone, Copy)]
pub struct Kdop<const N: usize>;
/// 14-DOP.
pub type Kdop14 = Kdop<7>;
/// 18-DOP.
pub type Kdop18 = Kdop<9>;
/// 26-DOP.
pub type Kdop26 = Kdop<13>;
