//! Support code for the workspace's acceptance tests in `tests/`.
