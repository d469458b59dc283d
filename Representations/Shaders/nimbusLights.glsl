// The view's own lights (lamps and spotlights, not the sun) in the Cloud's air and
// medium: their beams (nimbus::SpotProfile's twin), light maps (002 §6.2), shadow maps
// of the opaque scene, the transmittance toward them through the air and the cloud,
// and their single scattering along a view ray (002 Eq. 6: the integral of
// F(alpha) H(t) I_p(t) beta(t) dt) by equi-angular samples. Prepended after
// cloudLight.glsl to the passes that draw the lights (docs/lights.md).
// Units: positions in world units, distances converted to metres by metresPerUnit;
// lightIntensity in Y/sr of the sun's relative units (irradiance I / d^2 at d metres).
const int kMaxLights = 8;
uniform int lightCount;                  // 0: no light pass
uniform vec3 lightPosition[kMaxLights];  // world
uniform vec3 lightAxis[kMaxLights];      // unit, the beam's direction
uniform vec3 lightMapU[kMaxLights];      // the light map's frame (SpotLightMapFrame)
uniform vec3 lightMapV[kMaxLights];
uniform vec3 lightIntensity[kMaxLights]; // Y/sr, linear sRGB
// x: the cone's half angle [rad] (>= pi/2: a point light), y: the soft edge's inner
// angle [rad], z: tan(x), w: 1 when the light map applies to this light.
uniform vec4 lightCone[kMaxLights];
uniform vec2 lightConeCosines[kMaxLights]; // cos of the cone's half angle, of the inner angle
uniform sampler2D lightMap;              // luminance in r, v = 0 on the first row
uniform int lightShadowsOn;
uniform sampler2D lightShadowAtlas;      // depth; light i's six faces in row i
uniform mat3 lightUpToWorld;             // the up frame -> VTK's world (the maps' frame)
uniform vec2 lightShadowRange[kMaxLights]; // near, far plane (world units)
uniform vec2 lightShadowAtlasSize;       // faces per row (6), rows (lights)
uniform int lightCloudVolumeOn;          // the lights' transmittance volume is drawn
uniform sampler3D lightCloudVolume;      // light i's in [i, i + 1] / lightCount along z
uniform float lightCloudVolumeSlices;    // z-slices per light
uniform float lightRadiusMetres;         // distances to a light are at least this
uniform float lightMieScattering0;       // the air's Mie scattering at sea level [1/m]
uniform float lightPhaseConstant;        // k_multi / (4 pi) of the cloud's phase (000 Eq. 1)

bool LightIsSpot(int i)
{
  return lightCone[i].x < 0.5 * kPi;
}

// nimbus::SpotFactor: 1 within the inner angle, 0 beyond the cone, smoothstep between.
float LightSpotFactor(int i, vec3 w)
{
  if (!LightIsSpot(i))
  {
    return 1.0;
  }
  // The cosines first: the angle (an acos) only inside the soft edge.
  float cosine = clamp(dot(lightAxis[i], w), -1.0, 1.0);
  if (cosine <= lightConeCosines[i].x)
  {
    return 0.0;
  }
  if (cosine >= lightConeCosines[i].y)
  {
    return 1.0;
  }
  float angle = acos(cosine);
  float outer = max(lightCone[i].x, 0.0);
  float inner = lightCone[i].y;
  if (angle >= outer)
  {
    return 0.0;
  }
  if (angle <= inner)
  {
    return 1.0;
  }
  float t = (outer - angle) / (outer - inner);
  return t * t * (3.0 - 2.0 * t);
}

// nimbus::SpotLightMapCoordinates, then the map's luminance (0 outside it).
float LightMapFactor(int i, vec3 w)
{
  if (lightCone[i].w < 0.5 || !LightIsSpot(i))
  {
    return 1.0;
  }
  float along = dot(lightAxis[i], w);
  if (!(along > 0.0))
  {
    return 0.0;
  }
  vec2 uv = 0.5 + 0.5 * vec2(dot(w, lightMapU[i]), dot(w, lightMapV[i])) / (along * lightCone[i].z);
  if (any(lessThan(uv, vec2(0.0))) || any(greaterThan(uv, vec2(1.0))))
  {
    return 0.0;
  }
  return max(texture(lightMap, uv).r, 0.0);
}

// The face of a light's cube of shadow maps that sees direction v (ShadowFaces() in
// ViewLights.h: +x, -x, +y, -y, +z, -z), and v in that face's eye frame (x right,
// y up, z the distance along the face's axis).
int LightShadowFace(vec3 v, out vec3 eye)
{
  vec3 a = abs(v);
  if (a.x >= a.y && a.x >= a.z)
  {
    // Forward +-x, up +z, right = forward x up.
    eye = v.x > 0.0 ? vec3(-v.y, v.z, v.x) : vec3(v.y, v.z, -v.x);
    return v.x > 0.0 ? 0 : 1;
  }
  if (a.y >= a.z)
  {
    eye = v.y > 0.0 ? vec3(v.x, v.z, v.y) : vec3(-v.x, v.z, -v.y);
    return v.y > 0.0 ? 2 : 3;
  }
  // Forward +-z, up +y: right = forward x up = -x for +z, +x for -z.
  eye = v.z > 0.0 ? vec3(-v.x, v.y, v.z) : vec3(v.x, v.y, -v.z);
  return v.z > 0.0 ? 4 : 5;
}

// 1 where light i reaches p past the opaque scene, 0 in its shadow: the shadow map's
// depth compared at the four nearest texels and the results interpolated (a
// percentage-closer filter one texel wide).
float LightShadow(int i, vec3 p)
{
  if (lightShadowsOn == 0)
  {
    return 1.0;
  }
  vec3 eye;
  int face = LightShadowFace(lightUpToWorld * (p - lightPosition[i]), eye);
  float n = lightShadowRange[i].x, f = lightShadowRange[i].y;
  if (eye.z >= f)
  {
    return 1.0;
  }
  vec2 ndc = eye.xy / max(eye.z, 1e-30);
  vec2 faceSize = vec2(textureSize(lightShadowAtlas, 0)) / lightShadowAtlasSize;
  vec2 texel = (0.5 * ndc + 0.5) * faceSize - 0.5; // texel index within the face
  vec2 base = floor(texel);
  vec2 weight = texel - base;
  // The bias grows with the distance (a constant fraction of the depth's slope).
  float compareDepth = eye.z * (1.0 - 2e-3) - 2.0 * n;
  float lit[4];
  for (int k = 0; k < 4; ++k)
  {
    vec2 index = clamp(base + vec2(k & 1, k >> 1), vec2(0.0), faceSize - 1.0);
    ivec2 atlas = ivec2(index + vec2(float(face), float(i)) * faceSize);
    float depth = texelFetch(lightShadowAtlas, atlas, 0).r;
    // OpenGL's depth -> the distance along the face's axis.
    float z = 2.0 * f * n / ((f + n) - (2.0 * depth - 1.0) * (f - n));
    lit[k] = depth >= 1.0 || compareDepth <= z ? 1.0 : 0.0;
  }
  return mix(mix(lit[0], lit[1], weight.x), mix(lit[2], lit[3], weight.x), weight.y);
}

// The cloud's transmittance between p and light i, read in the light's transmittance
// volume (cloudLightDepthFS.glsl; lights stacked along its third axis) at the point of
// the segment from p to the light that lies in the density box nearest to p (beyond it,
// toward p, there is no cloud); 1 where the segment misses the box or without volume.
float LightCloudTransmittance(int i, vec3 p)
{
  if (lightCloudVolumeOn == 0)
  {
    return 1.0;
  }
  vec3 d = lightPosition[i] - p;
  float tIn, tOut;
  if (!BoxInterval(p, d, tIn, tOut) || tOut <= 0.0 || tIn >= 1.0)
  {
    return 1.0;
  }
  vec3 q = (worldToBox * vec4(p + max(tIn, 0.0) * d, 1.0)).xyz;
  float slices = lightCloudVolumeSlices;
  float w = clamp(q.z, 0.5 / slices, 1.0 - 0.5 / slices);
  return texture(lightCloudVolume, vec3(clamp(q.xy, 0.0, 1.0),
    (float(i) + w) / float(lightCount))).r;
}

// The clear air's transmittance between p and light i (000 Eq. 6, flat layers).
vec3 LightAirTransmittance(int i, vec3 p)
{
  if (atmosphereOn == 0)
  {
    return vec3(1.0);
  }
  vec3 d = lightPosition[i] - p;
  float distance = length(d) * metresPerUnit;
  float cosZenith = d.z / max(length(d), 1e-30);
  float h = Altitude(p);
  float lr = min(FlatLayerOpticalLength(h, cosZenith, distance, rayleighScaleHeightMetres), 1e30);
  float lm = min(FlatLayerOpticalLength(h, cosZenith, distance, mieScaleHeightMetres), 1e30);
  return exp(-(rayleighExtinction0 * lr + mieExtinction0 * lm));
}

// The light of light i arriving at p [irradiance on a surface facing it]: intensity,
// beam, light map, shadow map, the air between and (throughCloud) the cloud's
// transmittance between (LightCloudTransmittance, only where the beam reaches p);
// toLight: the unit direction from p toward the light.
vec3 LightArriving(int i, vec3 p, bool throughCloud, out vec3 toLight)
{
  vec3 d = lightPosition[i] - p;
  float distance = max(length(d) * metresPerUnit, lightRadiusMetres);
  toLight = d / max(length(d), 1e-30);
  float beam = LightSpotFactor(i, -toLight) * LightMapFactor(i, -toLight);
  if (beam <= 0.0)
  {
    return vec3(0.0);
  }
  float cloud = throughCloud ? LightCloudTransmittance(i, p) : 1.0;
  return lightIntensity[i] * beam * LightShadow(i, p) / (distance * distance) *
    LightAirTransmittance(i, p) * cloud;
}

// The part [a, b] of [t0, t1] inside light i's beam (a convex cone, or everything for a
// point light): the roots of (v.axis)^2 = cos^2 |v|^2 split the segment, and the
// pieces whose middle lies inside the forward cone are joined (the cone is convex).
bool LightInterval(int i, vec3 origin, vec3 direction, float t0, float t1, out float a, out float b)
{
  a = t0;
  b = t1;
  if (!LightIsSpot(i))
  {
    return t0 < t1;
  }
  vec3 axis = lightAxis[i];
  vec3 v = origin - lightPosition[i];
  float c2 = cos(lightCone[i].x);
  c2 *= c2;
  float da = dot(direction, axis), va = dot(v, axis);
  float qa = da * da - c2;
  float qb = 2.0 * (da * va - c2 * dot(direction, v));
  float qc = va * va - c2 * dot(v, v);
  float cuts[4];
  int count = 0;
  cuts[count++] = t0;
  if (abs(qa) > 1e-12)
  {
    float discriminant = qb * qb - 4.0 * qa * qc;
    if (discriminant > 0.0)
    {
      float s = sqrt(discriminant);
      float q = -0.5 * (qb + (qb >= 0.0 ? s : -s)); // stable roots
      float r0 = q / qa, r1 = abs(q) > 0.0 ? qc / q : r0;
      float lo = min(r0, r1), hi = max(r0, r1);
      if (lo > t0 && lo < t1) cuts[count++] = lo;
      if (hi > t0 && hi < t1 && hi > lo) cuts[count++] = hi;
    }
  }
  else if (abs(qb) > 0.0)
  {
    float r = -qc / qb;
    if (r > t0 && r < t1) cuts[count++] = r;
  }
  cuts[count++] = t1;
  a = kInfinity;
  b = -kInfinity;
  for (int k = 0; k + 1 < count; ++k)
  {
    float m = 0.5 * (cuts[k] + cuts[k + 1]);
    if (m > 1e20) m = cuts[k] + 1.0; // an unbounded piece: test a point on it
    vec3 w = v + m * direction;
    float along = dot(w, axis);
    if (along > 0.0 && along * along >= c2 * dot(w, w))
    {
      a = min(a, cuts[k]);
      b = max(b, cuts[k + 1]);
    }
  }
  return a < b;
}

// The air's scattering coefficient [1/m] and the weight of each phase at altitude h:
// Rayleigh (scattering = extinction) and Mie.
void AirScattering(float h, out vec3 rayleigh, out float mie)
{
  float height = max(h, 0.0);
  rayleigh = rayleighExtinction0 * exp(-height / rayleighScaleHeightMetres);
  mie = lightMieScattering0 * exp(-height / mieScaleHeightMetres);
}

// Light i's single scattering toward the eye per metre at p, by the air (Rayleigh and
// Mie) and by the cloud (sigma [1/m], its phase plus k_multi / 4 pi), before the view's
// attenuation, through the cloud's shadow.
vec3 LightScattering(int i, vec3 p, vec3 direction, float sigma, float mieG)
{
  vec3 toLight;
  vec3 arriving = LightArriving(i, p, true, toLight);
  float mu = clamp(dot(direction, toLight), -1.0, 1.0);
  vec3 rayleigh = vec3(0.0);
  float mie = 0.0;
  if (atmosphereOn != 0)
  {
    AirScattering(Altitude(p), rayleigh, mie);
  }
  return arriving * (rayleigh * Rayleigh(mu) + mie * CornetteShanks(mu, mieG) +
    cloudAlbedo * sigma * (CornetteShanks(mu, cloudG) + lightPhaseConstant));
}

// The part of the view ray inside each light's beam, [lightEnter[i], lightLeave[i]]
// (empty: enter > leave), set once per pixel by LightIntervalsAlong, so that the march's
// steps test two numbers instead of the beam's angle.
float lightEnter[kMaxLights];
float lightLeave[kMaxLights];
float lightsEnter; // the union's ends
float lightsLeave;

void LightIntervalsAlong(vec3 origin, vec3 direction, float t0, float t1)
{
  lightsEnter = kInfinity;
  lightsLeave = -kInfinity;
  for (int i = 0; i < lightCount; ++i)
  {
    float a, b;
    if (!LightInterval(i, origin, direction, t0, t1, a, b))
    {
      a = kInfinity;
      b = -kInfinity;
    }
    lightEnter[i] = a;
    lightLeave[i] = b;
    lightsEnter = min(lightsEnter, a);
    lightsLeave = max(lightsLeave, b);
  }
}

// The lights' light at p = origin + t direction in the cloud toward the eye per metre
// (sigma = k rho > 0); LightIntervalsAlong set the beams' intervals.
vec3 CloudLightsSource(vec3 p, float t, vec3 direction, float sigma)
{
  vec3 sum = vec3(0.0);
  for (int i = 0; i < lightCount; ++i)
  {
    if (t < lightEnter[i] || t > lightLeave[i])
    {
      continue;
    }
    vec3 toLight;
    vec3 arriving = LightArriving(i, p, true, toLight);
    float mu = clamp(dot(direction, toLight), -1.0, 1.0);
    sum += cloudAlbedo * sigma * (CornetteShanks(mu, cloudG) + lightPhaseConstant) * arriving;
  }
  return sum;
}

// The lights' light reflected by the Lambertian ground at g toward the eye, before the
// view's attenuation.
vec3 GroundLightsRadiance(vec3 g)
{
  vec3 sum = vec3(0.0);
  for (int i = 0; i < lightCount; ++i)
  {
    vec3 toLight;
    vec3 arriving = LightArriving(i, g, true, toLight);
    sum += groundAlbedo / kPi * max(toLight.z, 0.0) * arriving;
  }
  return sum;
}

// The clear air's transmittance between the eye and distance t along the pixel's ray:
// defined by the pass that draws the lights' shafts (the march reads its look-up volume).
vec3 LightsViewTransmittance(vec3 origin, vec3 direction, float t);

// The cloud's view transmittance ramp of LightsInAir (its log falls linearly from 0 at
// lightRampStart to its whole over lightRampLength).
float lightRampStart;
float lightRampLength;
float lightRampLog;

// The integrand of LightsInAir per unit angle theta about light i: the air's single
// scattering at t = closest + distance tan(theta) times dt/dtheta (metres), with the
// view's transmittance: the air's (LightsViewTransmittance), the cloud's as LightsInAir
// says. (Interpolating the air's geometrically between the beam's ends instead cost up
// to 2 % over a 400 m beam in fog, measured in TestCloudLights.)
vec3 LightAirIntegrand(
  int i, vec3 origin, vec3 direction, float theta, float closest, float distance, float mieG)
{
  float t = closest + distance * tan(theta);
  float c = cos(theta);
  vec3 p = origin + t * direction;
  float inCloud = clamp((t - lightRampStart) / max(lightRampLength, 1e-30), 0.0, 1.0);
  return LightScattering(i, p, direction, 0.0, mieG) *
    LightsViewTransmittance(origin, direction, t) * exp(lightRampLog * inCloud) *
    (distance / (c * c) * metresPerUnit);
}

// The lights' single scattering by the clear air along [t0, t1] of the view ray toward
// the eye [radiance], with the view's transmittance: the air's
// (LightsViewTransmittance) and the cloud's as 1 before cloudFirst,
// cloudTransmittance after cloudLast, interpolated geometrically between (the cloud's
// own lit particles are MarchCloud's). Samples per light equi-angular about the light
// (Kulla & Fajardo 2012): t = c + D tan(theta) with theta evenly spaced, so the 1/d^2 of
// the light's falloff is integrated exactly and the samples gather where the beam is
// bright; `samples` per light inside its beam, shifted by `jitter` in [0, 1) (per pixel,
// against banding). A shifted set of midpoints covers [a + (j - 1/2) h, b + (j - 1/2) h]:
// the two ends' integrands correct the sum for it, so the error stays of second order
// in h whatever the shift (measured in TestCloudLights: 0.5 % at 32 samples, against
// 11 % uncorrected).
vec3 LightsInAir(vec3 origin, vec3 direction, float t0, float t1, int samples, float jitter,
  float mieG, float cloudFirst, float cloudLast, float cloudTransmittance)
{
  vec3 sum = vec3(0.0);
  if (atmosphereOn == 0)
  {
    return sum;
  }
  lightRampStart = cloudFirst;
  lightRampLength = cloudLast - cloudFirst;
  lightRampLog = log(max(cloudTransmittance, 1e-30));
  float minimumDistance = lightRadiusMetres / metresPerUnit;
  for (int i = 0; i < lightCount; ++i)
  {
    float a, b;
    if (!LightInterval(i, origin, direction, t0, min(t1, 1e9), a, b))
    {
      continue;
    }
    // Beyond the distance at which the air has dimmed the view and the light's path by
    // e^-9 nothing adds up: the samples end there.
    vec3 extinction = min(AirExtinction(Altitude(origin)), AirExtinction(Altitude(lightPosition[i])));
    float thinnest = min(extinction.r, min(extinction.g, extinction.b));
    if (thinnest > 0.0)
    {
      b = min(b, max(a, 9.0 / (thinnest * metresPerUnit)));
    }
    float closest = dot(lightPosition[i] - origin, direction);
    float distance = max(length(lightPosition[i] - origin - closest * direction), minimumDistance);
    float thetaA = atan((a - closest) / distance);
    float thetaB = atan((b - closest) / distance);
    float dTheta = (thetaB - thetaA) / float(samples);
    vec3 light = vec3(0.0);
    for (int k = 0; k < samples; ++k)
    {
      light += LightAirIntegrand(
        i, origin, direction, thetaA + (float(k) + jitter) * dTheta, closest, distance, mieG);
    }
    vec3 ends = LightAirIntegrand(i, origin, direction, thetaA, closest, distance, mieG) -
      LightAirIntegrand(i, origin, direction, thetaB, closest, distance, mieG);
    sum += max(light + (jitter - 0.5) * ends, vec3(0.0)) * dTheta;
  }
  return sum;
}
