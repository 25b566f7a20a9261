"""The gearbox interior: Timoshenko shafts, coupling elements (RBE2/RBE3/star bores, bearings, gear mesh, tie
rods), the coupled housing + interior system and the `[coupling]` scene section."""
