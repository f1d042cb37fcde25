#pragma once
// plant/effects/effects.hpp -- every plant module beyond model (1), for callers that build
// plants from several (the case reader, tests). The interface is plant/effects/effect.hpp;
// each module has its own header here.
#include "plant/effects/current_saturation.hpp"
#include "plant/effects/effect.hpp"
#include "plant/effects/mechanical_mode.hpp"
#include "plant/effects/output_polynomial.hpp"
#include "plant/effects/pendulum_geometry.hpp"
#include "plant/effects/pickoff_nonlinearity.hpp"
#include "plant/effects/readout_clipping.hpp"
#include "plant/effects/squeeze_film_damping.hpp"
