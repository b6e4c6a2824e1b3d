SetFactory("OpenCASCADE");
Box(1) = {0.1, 0.1, 0.1, 0.5, 0.4, 0.3};
Mesh.CharacteristicLengthMax = 0.15;
Physical Volume("material 3 rock") = {1};
