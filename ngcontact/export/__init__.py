"""Export of a homogenized interface law to commercial FE codes (Abaqus, CalculiX, ANSYS) and to JSON."""
