// The ray-marched Cloud method: the whole picture of a pixel in one pass. The view
// ray is marched through the cloud box with a fixed step (jittered per pixel), the
// sun's transmittance read from the sun-depth volume (SunDepthVolume.h), only between
// the first and the last block that holds density (blockMaxima) and only until the
// cloud lets less than 1e-3 through. The air comes from the look-up volume of
// cloudAirFroxelsFS.glsl, and the cloud's shadow in it (the shafts) is marched only
// where it can fall (ShadowInterval). Output 0: (radiance before exposure, cloud
// transmittance; 0 where the ground closes the ray, not over a sky), as the slices and
// the march passes of the shadow-view-slice method leave it; output 1: the same without
// the cloud (read over a sky only; see svsCompositeFS.glsl); output 2: the cloud's span
// and the ray's end, for the lights' shafts on fewer pixels.
in vec2 texCoord;
uniform int unlit;                // benchmark floor: the cloud's optical depth alone
uniform int shaftsOn;
uniform int shaftSteps;           // most samples of the cloud's shadow in the air
uniform float shaftSpacing;       // their spacing where fewer suffice (world units)
uniform mat4 boxToTexture;        // the box as [0,1]^3 -> density texture coordinates
uniform float stepLength;         // the march's step (world units)
uniform int maxSteps;
uniform int maxBlockSteps;        // blocks a ray can cross
uniform vec3 densitySize;         // texels per axis
uniform sampler3D blockMaxima;    // the largest density a sample in each block can read
uniform float blockTexels;        // texels per block side
uniform vec3 blockCount;          // blocks per axis
uniform sampler2D froxelScattering;
uniform sampler2D froxelTransmittance;
uniform vec3 froxelDimensions;    // columns, rows, slices
ivec3 FroxelSize() { return ivec3(froxelDimensions + 0.5); }
uniform vec2 froxelDepths;        // d_1 (world units), 1 / log(d_{k+1} / d_k)
uniform float mieG;
uniform float multipleScattering; // k_multi (000 Eq. 1)
uniform int lightSamples;         // samples per view light along the ray (nimbusLights.glsl)
uniform int lightsInAir;          // 1: the lights' shafts in the air here; 0: another pass's

const float kOpaque = 1e-3;       // the cloud transmittance at which the march stops

// Where distance t falls on the look-up volume's ladder of distances (a slice index).
float FroxelSlice(float t)
{
  if (t <= froxelDepths.x)
  {
    return max(t, 0.0) / froxelDepths.x;
  }
  return min(1.0 + log(t / froxelDepths.x) * froxelDepths.y, float(FroxelSize().z - 1));
}

// Where distance t falls in the look-up volume's atlas: the texture coordinates of the
// two slices around it and the weight of the second.
void FroxelCoordinates(vec2 uv, float t, out vec2 c0, out vec2 c1, out float f)
{
  float s = FroxelSlice(min(t, 1e20));
  int k0 = int(floor(s));
  int k1 = min(k0 + 1, FroxelSize().z - 1);
  f = s - float(k0);
  vec2 xy = uv * vec2(FroxelSize().xy - 1) + 0.5; // texel units within a slice
  vec2 atlas = vec2(FroxelSize().x, FroxelSize().y * FroxelSize().z);
  c0 = vec2(xy.x, xy.y + float(k0 * FroxelSize().y)) / atlas;
  c1 = vec2(xy.x, xy.y + float(k1 * FroxelSize().y)) / atlas;
}

// The clear air's transmittance between the eye and distance t along this pixel's ray.
vec3 AirTransmittanceTo(vec2 uv, float t)
{
  if (atmosphereOn == 0)
  {
    return vec3(1.0);
  }
  vec2 c0, c1;
  float f;
  FroxelCoordinates(uv, t, c0, c1, f);
  return mix(texture(froxelTransmittance, c0).rgb, texture(froxelTransmittance, c1).rgb, f);
}

// The clear air between the eye and distance t along this pixel's ray: in-scattered
// radiance and transmittance, interpolated in the look-up volume.
void AirTo(vec2 uv, float t, out vec3 radiance, out vec3 transmittance)
{
  if (atmosphereOn == 0)
  {
    radiance = vec3(0.0);
    transmittance = vec3(1.0);
    return;
  }
  vec2 c0, c1;
  float f;
  FroxelCoordinates(uv, t, c0, c1, f);
  radiance = mix(texture(froxelScattering, c0).rgb, texture(froxelScattering, c1).rgb, f);
  transmittance = mix(texture(froxelTransmittance, c0).rgb, texture(froxelTransmittance, c1).rgb, f);
}

// The air's view transmittance for the lights' shafts (nimbusLights.glsl): from the
// look-up volume, as the rest of the march's air.
vec3 LightsViewTransmittance(vec3 origin, vec3 direction, float t)
{
  return AirTransmittanceTo(texCoord, t);
}

// The part [first, last] of [t0, t1] between the first and the last block that holds
// any density, by a 3-D DDA over the blocks (Amanatides & Woo 1987; one texel fetch per
// block): the march then steps only through it, with no test per step (on a GPU that
// runs pixels in lock-step, as llvmpipe does, a per-step test costs every pixel both
// of its branches). o + t d: the ray in texel index coordinates.
bool OccupiedSpan(vec3 o, vec3 d, float t0, float t1, out float first, out float last)
{
  first = kInfinity;
  last = -kInfinity;
  ivec3 count = ivec3(blockCount + 0.5);
  vec3 start = (o + (t0 + 1e-3 * stepLength) * d) / blockTexels;
  ivec3 block = clamp(ivec3(floor(start)), ivec3(0), count - 1);
  ivec3 stepDirection = ivec3(sign(d));
  vec3 safe = mix(d, vec3(1e-30), lessThan(abs(d), vec3(1e-30)));
  // The ray's t at the next block boundary per axis, and between two boundaries.
  vec3 boundary = (vec3(block) + step(0.0, d)) * blockTexels;
  vec3 tNext = mix((boundary - o) / safe, vec3(kInfinity), lessThan(abs(d), vec3(1e-30)));
  vec3 tDelta = mix(blockTexels / abs(safe), vec3(kInfinity), lessThan(abs(d), vec3(1e-30)));
  float t = t0;
  for (int i = 0; i < maxBlockSteps && t < t1; ++i)
  {
    float exit = min(tNext.x, min(tNext.y, tNext.z));
    if (texelFetch(blockMaxima, block, 0).r > 0.0)
    {
      first = min(first, t);
      last = exit;
    }
    t = exit;
    // Step across the nearest boundary.
    vec3 across = vec3(equal(tNext, vec3(exit)));
    block += ivec3(across) * stepDirection;
    tNext += across * tDelta;
    if (any(lessThan(block, ivec3(0))) || any(greaterThanEqual(block, count)))
    {
      break;
    }
  }
  last = min(last, t1);
  return first < last;
}

// The part [first, last] of the view ray between the first and the last density block
// it crosses inside the box's [t0, t1] (false when it crosses none).
bool CloudSpan(vec3 origin, vec3 direction, float t0, float t1, out float first, out float last)
{
  // Texel index coordinates of the ray, for the blocks.
  vec3 o = (worldToTexture * vec4(origin, 1.0)).xyz * densitySize - 0.5;
  vec3 d = (worldToTexture * vec4(direction, 0.0)).xyz * densitySize;
  return OccupiedSpan(o, d, t0, t1, first, last);
}

// The cloud along [first, last]: its radiance toward the eye (the clear air's
// transmittance from the eye included, interpolated geometrically between airIn at
// first and airOut at last) and its transmittance.
void MarchCloud(vec3 origin, vec3 direction, float first, float last, vec3 airIn,
  vec3 airOut, out vec3 radiance, out float transmittance)
{
  radiance = vec3(0.0);
  transmittance = 1.0;
  float mu = clamp(dot(direction, sunDirection), -1.0, 1.0);
  float cloudPhase = CornetteShanks(mu, cloudG) + multipleScattering / (4.0 * kPi);
  // The delta-M forward peak's term of SunMultipleScattering with the sun's transmittance
  // T read directly: (1 - f) p(mu) (T^(1 - f albedo) - T); the octaves keep the general form.
  float peakPhase = (1.0 - forwardPeakFraction) * CornetteShanks(mu, cloudG);
  float peakExponent = 1.0 - forwardPeakFraction * cloudAlbedo;
  float span = max(last - first, 1e-30);
  // log of the clear air's transmittance ratio across the span (geometric interpolation).
  vec3 airLogRatio = log(max(airOut, vec3(1e-30)) / max(airIn, vec3(1e-30)));
  float jitter = SliceJitterFraction(gl_FragCoord.xy) + 0.5; // in [0, 1)
  float stepMetres = stepLength * metresPerUnit;
  // The steps on the grid (n + jitter) stepLength from the ray's origin that fall in
  // [first, last]: anchored to the eye, not to the box, so the samples do not move with
  // the box's extent (cell or point data, a piece's bounds).
  float t = (ceil(first / stepLength - jitter) + jitter) * stepLength;
  // The delta-M view's lightning (CloudLightningDeltaM): its own transmittance through
  // the reduced extinction, alpha^(1 - f albedo) a step.
  float reducedShare = LightningReducedExtinction();
  float reducedTransmittance = lightningDeltaM != 0 ? 1.0 : 0.0;
  for (int i = 0; i < maxSteps && t < last; ++i)
  {
    vec3 p = origin + t * direction;
    float sigma = extinctionPerDensity * max(texture(density, (worldToTexture * vec4(p, 1.0)).xyz).r, 0.0);
    float alpha = exp(-sigma * stepMetres);
    // Exact integral of a constant source over the step: (1 - alpha) / sigma.
    float stepIntegral = sigma * stepMetres > 1e-4 ? (1.0 - alpha) / sigma : stepMetres;
    vec3 source = vec3(sigma);
    if (unlit == 0)
    {
      float sun = texture(sunDepthVolume, (worldToTexture * vec4(p, 1.0)).xyz).r; // T
      float beyond = octaves > 1 ? SunMultipleScattering(mu, -log(max(sun, 1e-37)))
        : forwardPeakFraction > 0.0 ? peakPhase * (pow(sun, peakExponent) - sun) : 0.0;
      source = (cloudAlbedo * sigma * (cloudPhase * sun + beyond) * SunIrradiance(Altitude(p)) +
                 CloudOtherSources(p, direction, sigma) +
                 (t >= lightsEnter && t <= lightsLeave ? CloudLightsSource(p, t, direction, sigma) : vec3(0.0))) *
        airIn * exp(airLogRatio * ((t - first) / span));
    }
    radiance += transmittance * source * stepIntegral;
    if (reducedTransmittance > 0.0 && unlit == 0 && sigma > 0.0)
    {
      float reducedSigma = reducedShare * sigma;
      float reducedAlpha = exp(-reducedSigma * stepMetres);
      float reducedIntegral =
        reducedSigma * stepMetres > 1e-4 ? (1.0 - reducedAlpha) / reducedSigma : stepMetres;
      radiance += reducedTransmittance * CloudLightningDeltaM(p, direction, sigma) * reducedIntegral *
        airIn * exp(airLogRatio * ((t - first) / span));
      reducedTransmittance *= reducedAlpha;
    }
    transmittance *= alpha;
    if (transmittance < kOpaque && reducedTransmittance < kOpaque)
    {
      transmittance = 0.0;
      break;
    }
    t += stepLength;
  }
}

// The sun's transmittance through the cloud at a point given in box coordinates
// (pb, the sun's direction lb there): read in the sun-depth volume where the point's
// line toward the sun enters the box, or at the point inside it; 1 where the line
// misses the box or leaves it away from the sun. No world-space matrix per call.
float SunTransmittanceAt(vec3 pb, vec3 lb)
{
  float tIn = -kInfinity, tOut = kInfinity;
  if (!ClipToUnitSlab(pb.x, lb.x, tIn, tOut) || !ClipToUnitSlab(pb.y, lb.y, tIn, tOut) ||
    !ClipToUnitSlab(pb.z, lb.z, tIn, tOut) || tIn > tOut || tOut < 0.0)
  {
    return 1.0;
  }
  vec3 entry = pb + max(tIn, 0.0) * lb;
  return texture(sunDepthVolume, (boxToTexture * vec4(entry, 1.0)).xyz).r;
}

// The sun's single scattering in the air that the cloud's shadow takes away along
// [a, b] (the part of the ray where a shadow can fall), with the view's clear-air
// transmittance and the air's single-scattering source interpolated geometrically
// between their values at a and b, and the cloud's transmittance toward the eye: 1
// before the cloud's first block (cloudFirst), cloudTransmittance behind its last
// (cloudLast), in between interpolated geometrically.
// Samples every shaftSpacing (four density texels), the spacing doubled until at most
// shaftSteps fall in [a, b]; placed on a grid anchored to the eye (as the march's steps), so
// they do not move with the interval's ends.
vec3 ShadowedAir(vec3 origin, vec3 direction, vec2 phase, float a, float b, vec3 airA,
  vec3 airB, float cloudFirst, float cloudLast, float cloudTransmittance)
{
  float span = b - a;
  float dt = shaftSpacing *
    exp2(max(ceil(log2(span / (shaftSpacing * float(max(shaftSteps, 1))))), 0.0));
  vec3 sourceA = AirSource(Altitude(origin + a * direction), phase);
  vec3 sourceB = AirSource(Altitude(origin + b * direction), phase);
  // log of the ratios b / a of the view's transmittance and of the source
  vec3 logRatio = log(max(airB, vec3(1e-30)) / max(airA, vec3(1e-30))) +
    log(max(sourceB, vec3(1e-30)) / max(sourceA, vec3(1e-30)));
  float logCloud = log(max(cloudTransmittance, 1e-30));
  // The ray and the sun in box coordinates.
  vec3 ob = (worldToBox * vec4(origin, 1.0)).xyz;
  vec3 db = (worldToBox * vec4(direction, 0.0)).xyz;
  vec3 lb = (worldToBox * vec4(sunDirection, 0.0)).xyz;
  float jitter = SliceJitterFraction(gl_FragCoord.xy) + 0.5;
  vec3 lost = vec3(0.0);
  float t = (ceil(a / dt - jitter) + jitter) * dt;
  for (int s = 0; s <= shaftSteps && t < b; ++s, t += dt)
  {
    float f = (t - a) / max(span, 1e-30);
    float inCloud = clamp((t - cloudFirst) / max(cloudLast - cloudFirst, 1e-30), 0.0, 1.0);
    lost += (1.0 - SunTransmittanceAt(ob + t * db, lb)) * exp(logRatio * f + logCloud * inCloud);
  }
  return sourceA * airA * lost * dt * metresPerUnit;
}

void main()
{
  vec3 origin, direction;
  ViewRay(texCoord, origin, direction);
  float tGround;
  float tEnd = RayEnd(texCoord, origin, direction, tGround);
  float tIn, tOut;
  bool hitsBox = BoxInterval(origin, direction, tIn, tOut) && tOut > 0.0 && tIn < tEnd;
  float t0 = max(tIn, 0.0), t1 = min(tOut, tEnd);
  vec3 airEnd, transmittanceEnd;
  AirTo(texCoord, tEnd, airEnd, transmittanceEnd);
  vec3 color = airEnd;      // the clear air, corrected below where the cloud is
  vec3 clearColor = airEnd; // without the cloud (over a sky)
  float cloudTransmittance = 1.0;
  // The cloud's blocks along the ray: [first, last] (empty: first = last = kInfinity).
  float first, last;
  bool cloudy = hitsBox && CloudSpan(origin, direction, t0, t1, first, last);
  if (!cloudy)
  {
    first = kInfinity;
    last = kInfinity;
  }
  else
  {
    vec3 airFirst, airLast, transmittanceFirst, transmittanceLast;
    AirTo(texCoord, first, airFirst, transmittanceFirst);
    AirTo(texCoord, last, airLast, transmittanceLast);
    vec3 cloudRadiance;
    lightsEnter = kInfinity;
    lightsLeave = -kInfinity;
    if (lightCount > 0 && unlit == 0)
    {
      LightIntervalsAlong(origin, direction, first, last);
    }
    MarchCloud(origin, direction, first, last, transmittanceFirst, transmittanceLast,
      cloudRadiance, cloudTransmittance);
    // The air in front of the cloud's first block as it is, the air between its first
    // and last block taken as spread evenly and dimmed by the cloud's transmittance at
    // their middle, the air behind the last block by the whole transmittance.
    color = airFirst + sqrt(cloudTransmittance) * (airLast - airFirst) +
      cloudTransmittance * (airEnd - airLast) + cloudRadiance;
    if (unlit != 0)
    {
      color = cloudRadiance;
    }
  }
  float a, b;
  if (unlit == 0 && shaftsOn != 0 && atmosphereOn != 0 &&
    ShadowInterval(origin, direction, 0.0, min(tEnd, 1e9), a, b))
  {
    vec3 airA = AirTransmittanceTo(texCoord, a);
    vec3 airB = AirTransmittanceTo(texCoord, b);
    float mu = clamp(dot(direction, sunDirection), -1.0, 1.0);
    vec2 phase = vec2(Rayleigh(mu), CornetteShanks(mu, mieG));
    color -= ShadowedAir(origin, direction, phase, a, b, airA, airB, first, last,
      cloudTransmittance);
    color = max(color, vec3(0.0));
  }
  if (unlit == 0 && lightCount > 0 && lightsInAir != 0)
  {
    color += LightsInAir(origin, direction, 0.0, tEnd, lightSamples,
      SliceJitterFraction(gl_FragCoord.xy) + 0.5, mieG, first, last, cloudTransmittance);
  }
  float alpha = cloudTransmittance;
  if (unlit == 0 && tGround < kInfinity && tGround <= tEnd)
  {
    vec3 g = origin + tGround * direction;
    // Behind (or inside) the cloud's blocks the ground is seen through the cloud.
    float through = tGround >= first ? cloudTransmittance : 1.0;
    vec3 ground = GroundRadiance(g, CloudDepthOutsideBox(g));
    color += (lightCount > 0 ? ground + GroundLightsRadiance(g) : ground) * transmittanceEnd * through;
    clearColor += GroundRadiance(g, 0.0) * transmittanceEnd;
    alpha = overSky != 0 ? cloudTransmittance : 0.0;
  }
  gl_FragData[0] = vec4(color, alpha);
  gl_FragData[1] = vec4(clearColor, 1.0);
  // For the lights' shafts drawn on fewer pixels (cloudLightShaftsFS.glsl).
  gl_FragData[2] = vec4(first, last, cloudTransmittance, tEnd);
}
