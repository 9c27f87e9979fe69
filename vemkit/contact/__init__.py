"""Contact with a deformable foundation: normal compliance (2.6) and Coulomb friction (2.7)-(2.9)."""
