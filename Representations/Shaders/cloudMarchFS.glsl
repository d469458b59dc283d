// The ray-marched Cloud method: the whole picture of a pixel in one pass. The view
// ray is marched through the cloud box with a fixed step (jittered per pixel), the
// sun's transmittance read from the sun-depth volume (SunDepthVolume.h), only between
// the first and the last block that holds density (blockMaxima) and only until the
// cloud lets less than 1e-4 through. The air comes from the look-up volume of cloudAirFroxelsFS.glsl, and
// the cloud's shadow in it (the shafts) is marched only where it can fall
// (ShadowInterval). Output 0: (radiance before exposure, cloud transmittance; 0 where
// the ground closes the ray, not over a sky), as the slices and the march passes of
// the shadow-view-slice method leave it; output 1: the same without the cloud (over
// a sky; see svsCompositeFS.glsl); output 2: (t_end, t_ground), the composite's.
in vec2 texCoord;
uniform int unlit;                // benchmark floor: the cloud's optical depth alone
uniform int shaftsOn;
uniform int shaftSteps;           // most samples of the cloud's shadow in the air
uniform float shaftSpacing;       // their spacing where fewer suffice (world units)
uniform float stepLength;         // the march's step (world units)
uniform int maxSteps;
uniform int maxBlockSteps;        // blocks a ray can cross
uniform vec3 densitySize;         // texels per axis
uniform sampler3D blockMaxima;    // the largest density a sample in each block can read
uniform float blockTexels;        // texels per block side
uniform vec3 blockCount;          // blocks per axis
uniform sampler2D froxelScattering;
uniform sampler2D froxelTransmittance;
uniform vec3 froxelDimensions; // columns, rows, slices
ivec3 FroxelSize() { return ivec3(froxelDimensions + 0.5); }
uniform vec2 froxelDepths;        // d_1 (world units), 1 / log(d_{k+1} / d_k)
uniform float mieG;
uniform float multipleScattering; // k_multi (000 Eq. 1)

const float kOpaque = 1e-4;       // the cloud transmittance at which the march stops

// Where distance t falls on the look-up volume's ladder of distances (a slice index).
float FroxelSlice(float t)
{
  if (t <= froxelDepths.x)
  {
    return max(t, 0.0) / froxelDepths.x;
  }
  return min(1.0 + log(t / froxelDepths.x) * froxelDepths.y, float(FroxelSize().z - 1));
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
  float s = FroxelSlice(min(t, 1e20));
  int k0 = int(floor(s));
  int k1 = min(k0 + 1, FroxelSize().z - 1);
  float f = s - float(k0);
  vec2 xy = uv * vec2(FroxelSize().xy - 1) + 0.5; // texel units within a slice
  vec2 atlas = vec2(FroxelSize().x, FroxelSize().y * FroxelSize().z);
  vec2 c0 = vec2(xy.x, xy.y + float(k0 * FroxelSize().y)) / atlas;
  vec2 c1 = vec2(xy.x, xy.y + float(k1 * FroxelSize().y)) / atlas;
  radiance = mix(texture(froxelScattering, c0).rgb, texture(froxelScattering, c1).rgb, f);
  transmittance = mix(texture(froxelTransmittance, c0).rgb, texture(froxelTransmittance, c1).rgb, f);
}

// The distance to where the ray leaves density block `block` (o + t d in texel index
// coordinates).
float BlockExit(vec3 o, vec3 d, vec3 block)
{
  vec3 lo = block * blockTexels, hi = lo + blockTexels;
  vec3 exits = vec3(kInfinity);
  for (int a = 0; a < 3; ++a)
  {
    if (d[a] > 1e-12)
    {
      exits[a] = (hi[a] - o[a]) / d[a];
    }
    else if (d[a] < -1e-12)
    {
      exits[a] = (lo[a] - o[a]) / d[a];
    }
  }
  return min(exits.x, min(exits.y, exits.z));
}

// The part [first, last] of [t0, t1] between the first and the last block that holds
// any density, by a walk over the blocks (one look-up each): the march then steps
// only through it, with no test per step (on a GPU that runs pixels in lock-step, as
// llvmpipe does, a per-step test costs every pixel its both branches).
bool OccupiedSpan(vec3 o, vec3 d, float t0, float t1, out float first, out float last)
{
  first = kInfinity;
  last = -kInfinity;
  float nudge = 1e-3 * stepLength;
  float t = t0;
  for (int i = 0; i < maxBlockSteps && t < t1; ++i)
  {
    vec3 block = floor((o + (t + nudge) * d) / blockTexels);
    float exit = max(BlockExit(o, d, block), t + nudge);
    if (texture(blockMaxima, (block + 0.5) / blockCount).r > 0.0)
    {
      first = min(first, t);
      last = exit;
    }
    t = exit;
  }
  last = min(last, t1);
  return first < last;
}

// The cloud along [t0, t1]: its radiance toward the eye (the clear air's transmittance
// from the eye included, interpolated geometrically between airIn and airOut) and its
// transmittance.
void MarchCloud(vec3 origin, vec3 direction, float t0, float t1, vec3 airIn, vec3 airOut,
  out vec3 radiance, out float transmittance)
{
  radiance = vec3(0.0);
  transmittance = 1.0;
  // Texel index coordinates of the ray, for the blocks.
  vec3 o = (worldToTexture * vec4(origin, 1.0)).xyz * densitySize - 0.5;
  vec3 d = (worldToTexture * vec4(direction, 0.0)).xyz * densitySize;
  float first, last;
  if (!OccupiedSpan(o, d, t0, t1, first, last))
  {
    return;
  }
  float mu = clamp(dot(direction, sunDirection), -1.0, 1.0);
  float cloudPhase = CornetteShanks(mu, cloudG) + multipleScattering / (4.0 * kPi);
  float span = max(t1 - t0, 1e-30);
  // log of the clear air's transmittance ratio across the box (geometric interpolation).
  vec3 airLogRatio = log(max(airOut, vec3(1e-30)) / max(airIn, vec3(1e-30)));
  float jitter = SliceJitterFraction(gl_FragCoord.xy) + 0.5; // in [0, 1)
  float stepMetres = stepLength * metresPerUnit;
  // The steps on the grid t0 + (n + jitter) stepLength that fall in [first, last].
  float t = t0 + (max(ceil((first - t0) / stepLength - jitter), 0.0) + jitter) * stepLength;
  for (int i = 0; i < maxSteps && t < last; ++i)
  {
    vec3 p = origin + t * direction;
    float sigma = extinctionPerDensity * max(texture(density, (worldToTexture * vec4(p, 1.0)).xyz).r, 0.0);
    float alpha = exp(-sigma * stepMetres);
    // Exact integral of a constant source over the step: (1 - alpha) / sigma.
    float stepIntegral = sigma * stepMetres > 1e-4 ? (1.0 - alpha) / sigma : stepMetres;
    vec3 source = unlit != 0 ? vec3(sigma)
      : CloudSource(p, direction, sigma, CloudDepthInsideBox(p), cloudPhase, Altitude(p)) *
        airIn * exp(airLogRatio * ((t - t0) / span));
    radiance += transmittance * source * stepIntegral;
    transmittance *= alpha;
    if (transmittance < kOpaque)
    {
      transmittance = 0.0;
      break;
    }
    t += stepLength;
  }
}

// The sun's single scattering in the air that the cloud's shadow takes away along
// [a, b] (the part of the ray where a shadow can fall), with the view's clear-air
// transmittance and the air's single-scattering source interpolated geometrically
// between their values at a and b, and the cloud's transmittance toward the eye: 1
// before the box, cloudTransmittance behind it, in between interpolated geometrically.
// One sample per shaftSpacing (two density texels), from shaftSteps / 2 to shaftSteps.
vec3 ShadowedAir(vec3 origin, vec3 direction, vec2 phase, float a, float b, vec3 airA,
  vec3 airB, float boxIn, float boxOut, float cloudTransmittance)
{
  float span = b - a;
  int count = int(clamp(ceil(span / shaftSpacing), float(max(shaftSteps / 2, 1)),
    float(max(shaftSteps, 1))));
  float dt = span / float(count);
  vec3 sourceA = AirSource(Altitude(origin + a * direction), phase);
  vec3 sourceB = AirSource(Altitude(origin + b * direction), phase);
  // log of the ratios b / a of the view's transmittance and of the source
  vec3 logAir = log(max(airB, vec3(1e-30)) / max(airA, vec3(1e-30)));
  vec3 logSource = log(max(sourceB, vec3(1e-30)) / max(sourceA, vec3(1e-30)));
  float logCloud = log(max(cloudTransmittance, 1e-30));
  float jitter = SliceJitterFraction(gl_FragCoord.xy) + 0.5;
  vec3 lost = vec3(0.0);
  for (int s = 0; s < count; ++s)
  {
    float t = a + (float(s) + jitter) * dt;
    vec3 p = origin + t * direction;
    float f = (t - a) / max(span, 1e-30);
    float inBox = clamp((t - boxIn) / max(boxOut - boxIn, 1e-30), 0.0, 1.0);
    float depth = InsideBox(p) ? CloudDepthInsideBox(p) : CloudDepthOutsideBox(p);
    lost += (1.0 - exp(-depth)) * exp(logCloud * inBox) * exp((logAir + logSource) * f);
  }
  return sourceA * airA * lost * dt * metresPerUnit;
}

void main()
{
  vec3 origin, direction;
  ViewRay(texCoord, origin, direction);
  float tGround = GroundDistance(origin, direction);
  float tEnd = min(min(OpaqueDistance(texCoord, origin, direction), TopDistance(origin, direction)),
    tGround);
  float tIn, tOut;
  bool hitsBox = BoxInterval(origin, direction, tIn, tOut) && tOut > 0.0 && tIn < tEnd;
  float t0 = max(tIn, 0.0), t1 = min(tOut, tEnd);
  vec3 airEnd, transmittanceEnd;
  AirTo(texCoord, tEnd, airEnd, transmittanceEnd);
  vec3 color = airEnd;      // the clear air, corrected below where the cloud is
  vec3 clearColor = airEnd; // without the cloud (over a sky)
  float cloudTransmittance = 1.0;
  vec3 air0 = vec3(0.0), air1 = vec3(0.0), transmittance0 = vec3(1.0), transmittance1 = vec3(1.0);
  if (hitsBox)
  {
    AirTo(texCoord, t0, air0, transmittance0);
    AirTo(texCoord, t1, air1, transmittance1);
    vec3 cloudRadiance;
    MarchCloud(origin, direction, t0, t1, transmittance0, transmittance1, cloudRadiance,
      cloudTransmittance);
    // The air in the box and behind it, seen through the cloud: the box's share taken
    // as spread evenly, dimmed by the cloud's transmittance at the box's middle.
    vec3 boxAir = air1 - air0;
    vec3 behindAir = airEnd - air1;
    color = air0 + sqrt(cloudTransmittance) * boxAir + cloudTransmittance * behindAir +
      cloudRadiance;
    if (unlit != 0)
    {
      color = cloudRadiance;
    }
  }
  float a, b;
  if (unlit == 0 && shaftsOn != 0 && atmosphereOn != 0 &&
    ShadowInterval(origin, direction, 0.0, min(tEnd, 1e9), a, b))
  {
    vec3 airA, airB, ignored;
    AirTo(texCoord, a, ignored, airA);
    AirTo(texCoord, b, ignored, airB);
    float mu = clamp(dot(direction, sunDirection), -1.0, 1.0);
    vec2 phase = vec2(Rayleigh(mu), CornetteShanks(mu, mieG));
    color -= ShadowedAir(origin, direction, phase, a, b, airA, airB, hitsBox ? t0 : kInfinity,
      hitsBox ? t1 : kInfinity, cloudTransmittance);
    color = max(color, vec3(0.0));
  }
  float alpha = cloudTransmittance;
  if (unlit == 0 && tGround < kInfinity && tGround <= tEnd)
  {
    vec3 g = origin + tGround * direction;
    // Behind (or inside) the box the ground is seen through the cloud.
    float through = hitsBox && tGround >= t0 ? cloudTransmittance : 1.0;
    color += GroundRadiance(g, CloudDepthOutsideBox(g)) * transmittanceEnd * through;
    clearColor += GroundRadiance(g, 0.0) * transmittanceEnd;
    alpha = overSky != 0 ? cloudTransmittance : 0.0;
  }
  gl_FragData[0] = vec4(color, alpha);
  gl_FragData[1] = vec4(clearColor, 1.0);
  gl_FragData[2] = vec4(tEnd, tGround, 0.0, 0.0);
}
