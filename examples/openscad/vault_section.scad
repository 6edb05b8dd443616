// A form-found vault's printable solid in OpenSCAD, cut open to show its section.
//
// Make the solid with the formfind example (STL, 3MF or OFF; the thickness in mesh units):
//   cargo run --release --example formfind -- ../shared/data/models/three_pillar.obj \
//       --supports ../shared/data/models/three_pillar.json --solid 0.05 three_pillar-solid.stl
// then open this file in OpenSCAD, or render it from the command line (OpenSCAD reads a
// relative path from this file's folder):
//   openscad -D "solid=\"$PWD/three_pillar-solid.stl\"" -o section.stl \
//       examples/openscad/vault_section.scad
// python/host_tests/test_openscad.py renders it.

solid = "three_pillar-solid.stl";  // formfind's --solid output
cut_y = 0;                       // keep the part with y <= cut_y (cut = false: all of it)
cut = true;
size = 1000;                     // larger than the vault

difference() {
  import(solid, convexity = 10);
  if (cut) translate([-size / 2, cut_y, -size / 2]) cube(size);
}
