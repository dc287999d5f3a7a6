// Cylinder of radius 0.5 and height 2 along z (volume pi/2); no physical groups.
SetFactory("OpenCASCADE");
Cylinder(1) = {0, 0, 0, 0, 0, 2, 0.5};
Mesh.CharacteristicLengthMax = 0.15;
