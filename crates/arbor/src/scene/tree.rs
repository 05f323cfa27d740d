//! (being written)
/// Placeholder element tree.
pub struct Node;
