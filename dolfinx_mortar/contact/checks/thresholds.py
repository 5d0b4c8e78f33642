"""The thresholds of the contact checks, in slave element lengths unless said."""

#: an initial penetration deeper than this many slave element lengths is warned about
DEEP_PENETRATION = 0.5
#: a penetration at convergence deeper than this many slave element lengths is
#: warned about: the penalty is low for the mesh (ε 1000× too low gave 0.055)
PENALTY_PENETRATION = 0.01
#: a node off the slave surface that has passed through a rigid obstacle by more
#: than this many lengths of its cells at convergence is warned about (logged)
BODY_PENETRATION = 0.25
#: the penetration, in element lengths, that the suggested penalty aims at
SUGGESTED_PENETRATION = 1e-3
#: basis_configuration="initial" is warned about past this many element lengths of slip
SLIP_LIMIT = 1.0
#: how many times a default search radius is widened (×4 each) before the
#: contact zone's reaching it is only warned about
MAX_RADIUS_WIDENINGS = 3
