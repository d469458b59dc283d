// Shared GLSL of the shadow-view-slice mapper (000). Prepended to each pass's
// fragment shader by vtkNimbusCloudVolumeMapper, after the GLSL library
// (nimbusPhase/Color/Atmosphere.glsl). World frame: z is up; lengths in world units,
// converted to metres with metresPerUnit. Radiometry: linear sRGB, relative to the
// sun (see Physics/Sun.h). Uniform names follow the C++ vocabulary (Physics/Sun.h,
// Atmosphere.h) and the sky shaders (sunDirection, cameraPosition, mieG).
uniform mat4 inverseViewProjection; // NDC -> world
uniform mat4 inverseViewProjectionFromEye; // NDC -> world relative to the eye
uniform int perspective;            // 1: rays start at the eye, 0: on the near plane
uniform vec3 cameraPosition;        // world position of the eye (perspective)
uniform vec3 viewForward;           // unit, the eye's -z axis in world (perspective)
uniform vec2 clippingRange;         // near, far (world units along viewForward)
uniform vec3 sunDirection;          // L, unit, toward the sun
uniform vec3 sliceNormal;           // n, unit, dot(n, -L) > 0
uniform float metresPerUnit;        // metres per world unit

uniform sampler3D density;          // cloud density volume
uniform mat4 worldToTexture;        // world -> density texture coordinates
uniform mat4 worldToBox;            // world -> [0,1]^3 over the density's box
uniform float extinctionPerDensity; // k_cl [1/m per density unit]
uniform float cloudAlbedo;          // sigma_s / sigma_t

uniform sampler2D shadowSurface;    // accumulated cloud optical depth toward the sun
uniform vec3 shadowOrigin;
uniform vec3 shadowU;
uniform vec3 shadowW;
uniform vec2 shadowExtent;
// The other pieces of a distributed cloud (ExternalShadow.h): optical depth
// toward the sun outside this piece, (beyond the piece toward the sun, whole line),
// on a map facing the sun over the whole cloud.
uniform int externalShadowOn;
uniform sampler2D externalShadow;
uniform vec3 externalOrigin;
uniform vec3 externalU;
uniform vec3 externalW;
uniform vec2 externalExtent;

uniform int atmosphereOn;
uniform sampler2D atmosphereTable;  // rows: sun, Rayleigh source, Mie source, extinction,
                                    // multiple-scattering source, ground sky irradiance
                                    // (AtmosphereTable.h)
uniform vec2 atmosphereZRange;      // z of the first and last column [m]
uniform vec3 rayleighExtinction0;   // sea level [1/m], per channel
uniform float mieExtinction0;       // sea level [1/m]
uniform float rayleighScaleHeightMetres;
uniform float mieScaleHeightMetres;
uniform float sceneAltitudeMetres;  // above sea level, of world z = 0
uniform float earthRadiusMetres;
uniform float topRadiusMetres;
uniform vec3 sunIrradianceTop;      // without atmosphere

uniform int groundOn;
uniform float groundZ;              // world z of the ground plane
uniform float groundAlbedo;

uniform sampler2D sceneDepth;       // depth of the opaque geometry already drawn
// Over a Nimbus sky the ground is the sky's too: it stays transparent in the
// accumulation's alpha, which is then the cloud's transmittance alone (nothing
// is accumulated behind the ground either way: rays end there).
uniform int overSky;
uniform int sliceJitter;            // 1: slice planes shifted per pixel (SliceJitter)
uniform float firstSliceOffset;     // d where the slicing starts: sunward of it, no shadow
// The ray-marched method (cloudMarchFS.glsl): the sun's transmittance through the cloud
// at every density texel (SunDepthVolume.h), in place of the shadow surface.
uniform int sunDepthVolumeOn;
uniform sampler3D sunDepthVolume;

const float kInfinity = 1e30;

// The shift of this pixel's (or shadow texel's) slice planes in units of the slice
// spacing, in [-1/2, 1/2): interleaved gradient noise (Jimenez 2014, "Next
// generation post processing in Call of Duty: Advanced Warfare"), whose
// neighbouring values are spread over the interval; 0 without SliceJitter.
float SliceJitterFraction(vec2 pixel)
{
  if (sliceJitter == 0)
  {
    return 0.0;
  }
  return fract(52.9829189 * fract(dot(pixel, vec2(0.06711056, 0.00583715)))) - 0.5;
}

void ViewRay(vec2 uv, out vec3 origin, out vec3 direction)
{
  vec2 ndc = 2.0 * uv - 1.0;
  // Perspective rays start at the eye, not on the near plane: the camera's
  // clipping range (ParaView fits it to the props' bounds) must not cut the
  // ground or the air between the eye and the cloud. Their direction is that of
  // the near-plane point relative to the eye: a far-plane point has w = 1/far,
  // which float rounds to 0 for far/near = 1e8 (NaN rays, a black frame).
  if (perspective != 0)
  {
    vec4 nearFromEye = inverseViewProjectionFromEye * vec4(ndc, -1.0, 1.0);
    origin = cameraPosition;
    direction = normalize(nearFromEye.xyz / nearFromEye.w);
    return;
  }
  vec4 nearPoint = inverseViewProjection * vec4(ndc, -1.0, 1.0);
  vec4 farPoint = inverseViewProjection * vec4(ndc, 1.0, 1.0);
  origin = nearPoint.xyz / nearPoint.w;
  direction = normalize(farPoint.xyz / farPoint.w - origin);
}

// Distance along the ray to the opaque geometry (infinity where none was drawn).
// Perspective: the eye depth in closed form, z = n / ((1 - n/f)(1 - d) + n/f) for
// depth d (OpenGL's projection), whose denominator stays >= n/f > 0 in float
// (unprojecting d through the inverse matrix divides by a w that cancels to 0).
float OpaqueDistance(vec2 uv, vec3 origin, vec3 direction)
{
  float depth = texture(sceneDepth, uv).r;
  if (depth >= 1.0)
  {
    return kInfinity;
  }
  if (perspective != 0)
  {
    float ratio = clippingRange.x / clippingRange.y;
    float eyeDepth = clippingRange.x / ((1.0 - ratio) * (1.0 - depth) + ratio);
    return eyeDepth / max(dot(direction, viewForward), 1e-6);
  }
  vec4 p = inverseViewProjection * vec4(2.0 * uv - 1.0, 2.0 * depth - 1.0, 1.0);
  return max(dot(p.xyz / p.w - origin, direction), 0.0);
}

float GroundDistance(vec3 origin, vec3 direction)
{
  if (groundOn == 0 || direction.z >= 0.0 || origin.z < groundZ)
  {
    return kInfinity;
  }
  return (groundZ - origin.z) / direction.z;
}

// Altitude above sea level over the spherical earth [m] of world point p.
float Altitude(vec3 p)
{
  vec3 q = vec3(p.xy * metresPerUnit, earthRadiusMetres + sceneAltitudeMetres + p.z * metresPerUnit);
  return length(q) - earthRadiusMetres;
}

// Distance (world units) to the top of the atmosphere from the ray origin.
float TopDistance(vec3 origin, vec3 direction)
{
  if (atmosphereOn == 0)
  {
    return kInfinity;
  }
  float r0 = earthRadiusMetres + sceneAltitudeMetres + origin.z * metresPerUnit;
  return DistanceToTopOfAtmosphere(r0, direction.z, topRadiusMetres) / metresPerUnit;
}

// Where the view ray through uv ends: opaque geometry, the ground or the top of the
// atmosphere (distance along the ray, world units); tGround: the ground's alone.
float RayEnd(vec2 uv, vec3 origin, vec3 direction, out float tGround)
{
  tGround = GroundDistance(origin, direction);
  return min(min(OpaqueDistance(uv, origin, direction), TopDistance(origin, direction)), tGround);
}

// Atmosphere table row at altitude h [m] (000: the "atmosphere texture").
vec3 AtmosphereRow(int row, float altitude)
{
  float z = altitude - sceneAltitudeMetres;
  float x = clamp((z - atmosphereZRange.x) / (atmosphereZRange.y - atmosphereZRange.x), 0.0, 1.0);
  ivec2 size = textureSize(atmosphereTable, 0);
  float u = (0.5 + x * float(size.x - 1)) / float(size.x);
  return texture(atmosphereTable, vec2(u, (float(row) + 0.5) / float(size.y))).rgb;
}

// Sun light scattered by the air per metre at altitude h toward the pixel's view
// direction, given the pixel's (Rayleigh, haze) phase values (000 Eq. 8, atmosphere).
vec3 AirSource(float altitude, vec2 rayleighAndHazePhase)
{
  return AtmosphereRow(1, altitude) * rayleighAndHazePhase.x +
    AtmosphereRow(2, altitude) * rayleighAndHazePhase.y;
}

// Light of the scattering orders >= 2 scattered by the air per metre at altitude h
// (isotropic: no phase factor; 0 when AirMultipleScattering is off). Not shadowed
// by the cloud: it comes from the whole sky, not from the sun's direction.
vec3 AirMultipleSource(float altitude)
{
  return AtmosphereRow(4, altitude);
}

vec3 SunIrradiance(float altitude)
{
  return atmosphereOn != 0 ? max(AtmosphereRow(0, altitude), vec3(0.0)) : sunIrradianceTop;
}

// Extinction of the air at altitude h [1/m] (the table's row 3 in closed form,
// the coefficients of AtmosphereViewTransmittance; 000 Eq. 6).
vec3 AirExtinction(float altitude)
{
  float h = max(altitude, 0.0);
  return rayleighExtinction0 * exp(-h / rayleighScaleHeightMetres) +
    mieExtinction0 * exp(-h / mieScaleHeightMetres);
}

// Atmospheric transmittance g_view_atm between the ray origin and distance t (000 Eq. 6).
vec3 AtmosphereViewTransmittance(vec3 origin, vec3 direction, float t)
{
  if (atmosphereOn == 0)
  {
    return vec3(1.0);
  }
  float h0 = sceneAltitudeMetres + origin.z * metresPerUnit;
  float tm = min(t, 1e7) * metresPerUnit;
  // Above the top of the atmosphere there is no air: the path starts where the ray
  // enters it. Otherwise, for an eye far above (1000 km), exp(-h0/H) underflows
  // to 0 while the layer factor overflows to infinity: 0 x inf = NaN.
  float topAltitude = topRadiusMetres - earthRadiusMetres;
  if (h0 > topAltitude)
  {
    if (direction.z >= 0.0)
    {
      return vec3(1.0);
    }
    tm -= (h0 - topAltitude) / -direction.z;
    h0 = topAltitude;
    if (tm <= 0.0)
    {
      return vec3(1.0);
    }
  }
  // Capped: a ray far below sea level (no ground) has an infinite optical length,
  // which times a zero coefficient would be NaN; 1e30 gives transmittance 0 alike.
  float lr = min(FlatLayerOpticalLength(h0, direction.z, tm, rayleighScaleHeightMetres), 1e30);
  float lm = min(FlatLayerOpticalLength(h0, direction.z, tm, mieScaleHeightMetres), 1e30);
  return exp(-(rayleighExtinction0 * lr + mieExtinction0 * lm));
}

// Narrows [tIn, tOut] to the t where 0 <= o + t d <= 1 (one slab of a unit box);
// false when a line parallel to the slab lies outside it.
bool ClipToUnitSlab(float o, float d, inout float tIn, inout float tOut)
{
  if (abs(d) < 1e-30)
  {
    return o >= 0.0 && o <= 1.0;
  }
  float a = -o / d;
  float b = (1.0 - o) / d;
  tIn = max(tIn, min(a, b));
  tOut = min(tOut, max(a, b));
  return true;
}

// The interval [tIn, tOut] of the ray origin + t direction inside the box that
// `toBox` maps onto [0,1]^3 (t may be negative); false when the ray's line misses it.
bool BoxIntervalOf(mat4 toBox, vec3 origin, vec3 direction, out float tIn, out float tOut)
{
  vec3 o = (toBox * vec4(origin, 1.0)).xyz;
  vec3 d = (toBox * vec4(direction, 0.0)).xyz;
  tIn = -kInfinity;
  tOut = kInfinity;
  return ClipToUnitSlab(o.x, d.x, tIn, tOut) && ClipToUnitSlab(o.y, d.y, tIn, tOut) &&
    ClipToUnitSlab(o.z, d.z, tIn, tOut) && tIn <= tOut;
}

// The same for the cloud box.
bool BoxInterval(vec3 origin, vec3 direction, out float tIn, out float tOut)
{
  return BoxIntervalOf(worldToBox, origin, direction, tIn, tOut);
}

// The air's sea-level-equivalent optical lengths [m] (Rayleigh, Mie) from the eye to
// where the view ray enters the cloud box (0 when the eye is inside it or the ray
// misses it), over the spherical earth: summed as the march sums them in front of the
// box (samples dense toward the box, the altitude of each over the sphere), so that
// the slices, which continue from there in closed form (BoxViewTransmittance), see
// the air beside the box attenuated as the march does, however far the box is: the
// flat-layer closed form from the eye drifts from the sphere by a few per cent of the
// optical length 20 km away at a low elevation (TestAtmosphere). From the top of the
// atmosphere for an eye above it.
vec2 BoxEntryOpticalLengths(vec3 origin, vec3 direction, float tEnd, int count)
{
  float tIn, tOut;
  if (atmosphereOn == 0 || !BoxInterval(origin, direction, tIn, tOut) || tIn <= 0.0 ||
    tOut <= 0.0)
  {
    return vec2(0.0);
  }
  float t1 = min(tIn, tEnd);
  // Where the ray enters the atmosphere (an eye above its top).
  vec3 q = vec3(origin.xy * metresPerUnit,
    earthRadiusMetres + sceneAltitudeMetres + origin.z * metresPerUnit);
  float r = length(q);
  float t0 = 0.0;
  if (r > topRadiusMetres)
  {
    float mu = dot(direction, q / r);
    float disc = r * r * mu * mu - (r * r - topRadiusMetres * topRadiusMetres);
    if (mu >= 0.0 || disc < 0.0)
    {
      return vec2(0.0); // never enters the air
    }
    t0 = (-r * mu - sqrt(disc)) / metresPerUnit;
  }
  float span = t1 - t0;
  vec2 lengths = vec2(0.0);
  int n = max(count, 16);
  for (int k = 0; k < n && span > 0.0; ++k)
  {
    float u = (float(k) + 0.5) / float(n);
    float t = t1 - span * (1.0 - u) * (1.0 - u); // dense toward the box
    float dt = span * 2.0 * (1.0 - u) / float(n) * metresPerUnit;
    float h = max(Altitude(origin + t * direction), 0.0);
    lengths += exp(-h / vec2(rayleighScaleHeightMetres, mieScaleHeightMetres)) * dt;
  }
  return lengths;
}

// Atmospheric transmittance between the eye and distance t >= the box entry along
// the view ray: BoxEntryOpticalLengths (ends.ba, from the ray-ends texture), then the
// flat-layer closed form from the entry point, at its altitude and zenith angle over
// the sphere. Rays that start inside the box (or miss it): AtmosphereViewTransmittance.
vec3 BoxViewTransmittance(vec3 origin, vec3 direction, float t, vec2 entryLengths)
{
  float tIn, tOut;
  if (atmosphereOn == 0 || !BoxInterval(origin, direction, tIn, tOut) || tIn <= 0.0)
  {
    return AtmosphereViewTransmittance(origin, direction, t);
  }
  vec3 entry = origin + tIn * direction;
  vec3 q = vec3(entry.xy * metresPerUnit,
    earthRadiusMetres + sceneAltitudeMetres + entry.z * metresPerUnit);
  float r = length(q);
  float h = r - earthRadiusMetres;
  float cosZenith = dot(direction, q / r);
  float d = min(max(t - tIn, 0.0), 1e7) * metresPerUnit;
  float lr = min(entryLengths.x + FlatLayerOpticalLength(h, cosZenith, d, rayleighScaleHeightMetres), 1e30);
  float lm = min(entryLengths.y + FlatLayerOpticalLength(h, cosZenith, d, mieScaleHeightMetres), 1e30);
  return exp(-(rayleighExtinction0 * lr + mieExtinction0 * lm));
}

bool InsideBox(vec3 p)
{
  vec3 box = (worldToBox * vec4(p, 1.0)).xyz;
  return all(greaterThanEqual(box, vec3(0.0))) && all(lessThanEqual(box, vec3(1.0)));
}

float CloudDensity(vec3 p)
{
  if (!InsideBox(p))
  {
    return 0.0;
  }
  return max(texture(density, (worldToTexture * vec4(p, 1.0)).xyz).r, 0.0);
}

// Cloud optical depth toward the sun accumulated on the shadow surface so far.
float ShadowDepth(vec3 p)
{
  vec3 q = p - shadowOrigin;
  vec2 st = vec2(dot(q, shadowU), dot(q, shadowW)) / shadowExtent;
  if (any(lessThan(st, vec2(0.0))) || any(greaterThan(st, vec2(1.0))))
  {
    return 0.0;
  }
  return texture(shadowSurface, st).r;
}

// The other pieces' optical depth toward the sun on p's sun line (0 without them):
// .x beyond this piece (for points inside it), .y the whole line outside it.
vec2 ExternalDepths(vec3 p)
{
  if (externalShadowOn == 0)
  {
    return vec2(0.0);
  }
  vec3 q = p - externalOrigin;
  vec2 st = vec2(dot(q, externalU), dot(q, externalW)) / externalExtent;
  if (any(lessThan(st, vec2(0.0))) || any(greaterThan(st, vec2(1.0))))
  {
    return vec2(0.0);
  }
  return texture(externalShadow, st).rg;
}

// The cloud's optical depth toward the sun at a point of the box: the ray march's
// sun-depth volume, or the slices' shadow surface so far.
float OwnDepthInsideBox(vec3 p)
{
  if (sunDepthVolumeOn != 0)
  {
    // The texture holds the transmittance exp(-tau) (SunDepthVolume.h); 1e-37 keeps
    // tau finite (85) where the sun is gone.
    return -log(max(texture(sunDepthVolume, (worldToTexture * vec4(p, 1.0)).xyz).r, 1e-37));
  }
  return ShadowDepth(p);
}

// Cloud optical depth toward the sun of a point inside the box: this piece's slices
// so far (or the sun-depth volume), plus the other pieces' beyond it.
float CloudDepthInsideBox(vec3 p)
{
  return OwnDepthInsideBox(p) + ExternalDepths(p).x;
}

// Cloud optical depth toward the sun of a point outside the box, once the shadow
// surface is complete (see svsMarchFS.glsl): the whole sun line's when the line
// toward the sun meets the box, else 0; plus the other pieces' on the whole line.
// With the sun-depth volume: its value where the sun line enters the box.
float CloudDepthOutsideBox(vec3 p)
{
  float tIn, tOut;
  float own = 0.0;
  if (BoxInterval(p, sunDirection, tIn, tOut) && tOut >= 0.0)
  {
    own = sunDepthVolumeOn != 0 ? OwnDepthInsideBox(p + max(tIn, 0.0) * sunDirection)
                                : ShadowDepth(p);
  }
  return own + ExternalDepths(p).y;
}

// The part [a, b] of [t0, t1] where the ray can be in the cloud's shadow: its sun
// line crosses the shadow surface's rectangle, and it is past the first slice
// plane (sunward of that plane the line toward the sun never meets the box).
bool ShadowInterval(vec3 origin, vec3 direction, float t0, float t1, out float a, out float b)
{
  a = t0;
  b = t1;
  // With other pieces, their shadow's rectangle: it covers the whole cloud.
  vec3 rectOrigin = externalShadowOn != 0 ? externalOrigin : shadowOrigin;
  vec3 rectU = externalShadowOn != 0 ? externalU : shadowU;
  vec3 rectW = externalShadowOn != 0 ? externalW : shadowW;
  vec2 rectExtent = externalShadowOn != 0 ? externalExtent : shadowExtent;
  vec3 q = origin - rectOrigin;
  vec2 s0 = vec2(dot(q, rectU), dot(q, rectW)) / rectExtent;
  vec2 ds = vec2(dot(direction, rectU), dot(direction, rectW)) / rectExtent;
  if (!ClipToUnitSlab(s0.x, ds.x, a, b) || !ClipToUnitSlab(s0.y, ds.y, a, b))
  {
    return false;
  }
  float vn = dot(direction, sliceNormal);
  float d0 = dot(origin, sliceNormal);
  if (abs(vn) < 1e-30)
  {
    return d0 >= firstSliceOffset && a < b;
  }
  float tPlane = (firstSliceOffset - d0) / vn;
  if (vn > 0.0)
  {
    a = max(a, tPlane);
  }
  else
  {
    b = min(b, tPlane);
  }
  return a < b;
}

// Radiance of the Lambertian ground at g, toward the eye, before view attenuation.
vec3 GroundRadiance(vec3 g, float cloudDepthToSun)
{
  float cosSun = max(sunDirection.z, 0.0);
  vec3 radiance = groundAlbedo / kPi * cosSun * SunIrradiance(Altitude(g)) *
    exp(-cloudDepthToSun);
  if (atmosphereOn != 0)
  {
    // The sky's light (AirMultipleScattering; 0 when off), not shadowed by the cloud.
    radiance += groundAlbedo / kPi * AtmosphereRow(5, Altitude(g));
  }
  return radiance;
}
