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
// closed form), the density constant below sea level: the path splits where it
// crosses h = 0. The exponential part uses the series for |x| = |l cosZenith / H| < 1e-2
// (truncation error x^4/120 < 1e-10 relative; in float 1 - exp(-x) would lose 6e-5
// relative at 1e-3).
float ExponentialLayerLength(float h, float cosZenith, float distance, float scaleHeight)
{
  float x = distance * cosZenith / scaleHeight;
  float factor = abs(x) < 1e-2 ? distance * (1.0 - x / 2.0 + x * x / 6.0 - x * x * x / 24.0)
                               : scaleHeight * (1.0 - exp(-x)) / cosZenith;
  return exp(-h / scaleHeight) * factor;
}

float FlatLayerOpticalLength(float altitude, float cosZenith, float distance, float scaleHeight)
{
  float below = 0.0;
  float start = altitude;
  float len = distance;
  if (altitude < 0.0)
  {
    if (!(cosZenith > 0.0))
    {
      return distance; // never rises above sea level
    }
    below = min(distance, -altitude / cosZenith);
    start = 0.0;
    len = distance - below;
  }
  else if (cosZenith < 0.0)
  {
    len = min(distance, altitude / -cosZenith);
    below = distance - len;
  }
  return below + ExponentialLayerLength(start, cosZenith, len, scaleHeight);
}
