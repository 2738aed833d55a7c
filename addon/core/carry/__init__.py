"""What a mesh looks like and how it is carried through a decimation: appearance attributes in
the collapse cost, UVs, colours and materials out, edge flags, OBJ material libraries, normal bakes."""
