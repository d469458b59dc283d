// Atmosphere geometry and optical lengths: the GLSL twins of Physics/Atmosphere.h
// (nimbus::DistanceToTopOfAtmosphere, nimbus::FlatLayerOpticalLength), the same
// steps, compared with them by the test TestShaderTwins. Lengths in metres.

// Distance from radius r along zenith cosine mu to the sphere of radius topRadius
// (0 when the ray misses it).
float DistanceToTopOfAtmosphere(float r, float mu, float topRadius)
{
  float b = r * mu;
  float c = (r - topRadius) * (r + topRadius);
  float disc = b * b - c;
  if (disc < 0.0)
  {
    return 0.0;
  }
  return max(-b + sqrt(disc), 0.0);
}

// Sea-level-equivalent length of an exponential layer (scale height H) along a
// straight ray of length d from altitude h0 in a flat atmosphere (000 Eq. 6 in
// closed form), with the series for |x| = |d cosZenith / H| < 1e-2 (truncation error
// x^4/120 < 1e-10 relative; in float 1 - exp(-x) would lose 6e-5 relative at 1e-3).
float FlatLayerOpticalLength(float altitude, float cosZenith, float distance, float scaleHeight)
{
  float x = distance * cosZenith / scaleHeight;
  float factor = abs(x) < 1e-2 ? distance * (1.0 - x / 2.0 + x * x / 6.0 - x * x * x / 24.0)
                               : scaleHeight * (1.0 - exp(-x)) / cosZenith;
  return exp(-max(altitude, 0.0) / scaleHeight) * factor;
}
