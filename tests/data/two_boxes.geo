// Two unit cubes side by side sharing a face: two physical volumes (tags 1 and 2).
SetFactory("OpenCASCADE");
Box(1) = {0, 0, 0, 1, 1, 1};
Box(2) = {1, 0, 0, 1, 1, 1};
BooleanFragments{ Volume{1}; Delete; }{ Volume{2}; Delete; }
Physical Volume(1) = {1};
Physical Volume(2) = {2};
Mesh.CharacteristicLengthMax = 0.25;
