"""Joint-space dynamics of fixed-base chains: Featherstone's recursive algorithms and the lecture's Jacobian sum."""
