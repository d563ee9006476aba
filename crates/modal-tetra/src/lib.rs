//! `modal-tetra`: surface meshes (OBJ/STL/PLY) in, quality tet meshes out.
