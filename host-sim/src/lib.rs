//! ph-formation host simulator.
