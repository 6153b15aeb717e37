//! Host test suite for trackbelt (see tests/).
