// The built-in surface catalogue (docs/ALGORITHM.md "Evaluation protocol",
// paper Sects. 5.2-5.3). Each factory documents its formula over its native
// parameter box; the box is mapped linearly onto the unit square.
//
// Thread-safety: the returned surfaces are immutable and thread-safe.
#ifndef SFCSAMPLER_CORE_BUILTIN_SURFACES_H_
#define SFCSAMPLER_CORE_BUILTIN_SURFACES_H_

#include <memory>

#include "core/surface.h"

namespace sfc {

// Unit square in the z = 0 plane: f(u,v) = (u, v, 0), (u,v) in [0,1]^2.
std::unique_ptr<Surface> MakePlane();

// Sphere of radius r: theta = pi u in [0,pi], phi = 2 pi v in [0,2pi],
// f = r (sin theta cos phi, sin theta sin phi, cos theta). REQUIRES: r > 0.
std::unique_ptr<Surface> MakeSphere(double radius);

// Torus: a = 2 pi u, b = 2 pi v, f = ((R + r cos b) cos a, (R + r cos b) sin a,
// r sin b). REQUIRES: R > 0, r > 0.
std::unique_ptr<Surface> MakeTorus(double major_radius, double minor_radius);

// Monkey saddle: (s,t) in [-1,1]^2, f = (s, t, s^3 - 3 s t^2).
std::unique_ptr<Surface> MakeMonkeySaddle();

// Eight surface: a in [0,2pi], b in [-pi/2,pi/2],
// f = (cos a sin 2b, sin a sin 2b, sin b).
std::unique_ptr<Surface> MakeEightSurface();

// Whitney umbrella: (s,t) in [-1,1]^2, f = (s t, s, t^2).
std::unique_ptr<Surface> MakeWhitneyUmbrella();

// Superellipsoid (paper Sect. 5.3) with signed powers c^e = sign(c)|c|^e:
// a in [-pi/2,pi/2], b in [-pi,pi],
// f = (cos^e a cos^e b, cos^e a sin^e b, sin^e a). The paper's case is e = 1/3.
//
// With `power_reparameterisation`, each quarter-turn piece of a and b is
// reparameterised by the power law of Sect. 5.3 applied at both of its ends:
// angle = piece_start + (pi/2) s^3 / (s^3 + (1-s)^3) for the piece-local s in
// [0,1]. Near a zero of sin or cos this behaves like the paper's u = u'^3 pi/2,
// so sin^(1/3) and cos^(1/3) become smooth in s. REQUIRES: e > 0.
std::unique_ptr<Surface> MakeSuperellipsoid(double exponent, bool power_reparameterisation);

}  // namespace sfc

#endif  // SFCSAMPLER_CORE_BUILTIN_SURFACES_H_
