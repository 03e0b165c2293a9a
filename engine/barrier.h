// A screen's attenuation as standards give it, for paths round edges in series
// (engine/edge_chain.h) and for a first-order path that just clears a second edge.
//
// Internal to the engine. Any thread; pure functions; no allocation; no errors.
#pragma once

namespace dpc {

/// ISO 9613-2:1996's factor C3 for diffraction over edges `span` metres apart (first to last)
/// at wavelength lambda (m): (1 + (5 lambda / e)^2) / (1/3 + (5 lambda / e)^2), from 1 (edges
/// much closer than a wavelength act as one) to 3 (far apart).
double multipleEdgeFactor(double lambda, double span);

/// ISO 9613-2:1996 eq. (14) as an energy ratio over the free field at the direct distance:
/// 10^(-Dz / 10) = 1 / (3 + (C2 / lambda) C3 z), z (m) the path's excess over the direct
/// distance, C2 = 40 (reflections modelled apart, not part of the screen term), C3 =
/// multipleEdgeFactor(lambda, span) for `edges` >= 2 and 1 for one; meteorological
/// correction 1 (indoors), no upper limit. 1/3 (4.8 dB) on the shadow boundary.
double screenGain(double lambda, double z, double span, int edges);

/// The amplitude factor of a field that passes an edge on its lit side with path-length excess
/// `excess` (m), `span` metres past the edge it diffracted from, at wavelength lambda (m): the
/// knife edge's lit-side transition J(v) = 6.9 + 20 lg(sqrt((v - 0.1)^2 + 1) + v - 0.1) dB for
/// v > -0.78 and 0 below (ITU-R P.526-15 eq. (31)), v = -2 sqrt(excess / lambda) (the
/// clearance's Fresnel-Kirchhoff parameter), in the proportion (C3 - 1) / 2 of its decibels
/// (multipleEdgeFactor): the whole 6 dB on the shadow boundary where the edges are many
/// wavelengths apart, none where they act as one. 1 for a negative excess (none).
double grazingAmplitude(double excess, double span, double lambda);

}  // namespace dpc
