//! Quality metrics of quad and hex cells and whole meshes.
