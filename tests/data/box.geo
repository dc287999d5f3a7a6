// A 2 x 1 x 0.5 box (volume 1), one physical volume with tag 7.
SetFactory("OpenCASCADE");
Box(1) = {0, 0, 0, 2, 1, 0.5};
Physical Volume(7) = {1};
Mesh.CharacteristicLengthMax = 0.2;
