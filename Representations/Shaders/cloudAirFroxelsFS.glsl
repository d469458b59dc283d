// The clear air as a look-up volume over the view (the ray-marched Cloud method;
// Hillaire 2020, "A Scalable and Production Ready Sky and Atmosphere Rendering
// Technique", §5.4: the aerial-perspective volume): for a coarse grid of view
// directions and a ladder of distances d_k along each, the air's in-scattered
// radiance from the eye to d_k (single scattering of the sun, unshadowed, plus the
// isotropic multiple scattering of the atmosphere table: 000 Eq. 8, atmosphere) and
// its transmittance. The cloud's shadow in the air (the shafts) is not in it:
// cloudMarchFS.glsl takes it off per pixel where a shadow can fall.
//
// Layout: a 2-D atlas of froxelDimensions.z slices, each froxelDimensions.x columns by
// froxelDimensions.y rows, slice k above slice k - 1. Texel (i, j) of a slice is the view
// ray through
// uv = (i, j) / (columns - 1, rows - 1), so the corner texels are the view's corners.
// Distances: d_0 = 0, d_k = froxelDepths.x * exp((k - 1) / froxelDepths.y) (world units;
// cloudMarchFS.glsl's FroxelSlice inverts it). Output 0: rgb in-scattered radiance;
// output 1: rgb transmittance.
in vec2 texCoord;
uniform vec3 froxelDimensions; // columns, rows, slices
ivec3 FroxelSize() { return ivec3(froxelDimensions + 0.5); }
uniform vec2 froxelDepths;     // d_1 (world units), 1 / log(d_{k+1} / d_k)
uniform int stepsPerInterval;  // samples between two distances of the ladder
uniform float mieG;

void main()
{
  ivec2 texel = ivec2(texCoord * vec2(FroxelSize().x, FroxelSize().y * FroxelSize().z));
  int slice = texel.y / FroxelSize().y;
  ivec2 ij = ivec2(texel.x, texel.y - slice * FroxelSize().y);
  vec2 uv = vec2(ij) / vec2(max(FroxelSize().xy - 1, ivec2(1)));
  vec3 origin, direction;
  ViewRay(uv, origin, direction);
  float mu = clamp(dot(direction, sunDirection), -1.0, 1.0);
  vec2 phase = vec2(Rayleigh(mu), CornetteShanks(mu, mieG));
  vec3 radiance = vec3(0.0);
  vec3 transmittance = vec3(1.0);
  float previous = 0.0;
  for (int k = 1; k <= slice; ++k)
  {
    float next = froxelDepths.x * exp(float(k - 1) / froxelDepths.y);
    float dt = (next - previous) / float(stepsPerInterval);
    float dtMetres = dt * metresPerUnit;
    for (int s = 0; s < stepsPerInterval; ++s)
    {
      vec3 p = origin + (previous + (float(s) + 0.5) * dt) * direction;
      float altitude = Altitude(p);
      vec3 source = AirSource(altitude, phase) + AirMultipleSource(altitude);
      vec3 extinction = AirExtinction(altitude);
      vec3 stepTransmittance = exp(-extinction * dtMetres);
      // Exact for constant coefficients over the step: (1 - T_step) / k_atm.
      vec3 weight = mix(vec3(dtMetres), (1.0 - stepTransmittance) / max(extinction, vec3(1e-30)),
        step(vec3(1e-4), extinction * dtMetres));
      radiance += source * transmittance * weight;
      transmittance *= stepTransmittance;
    }
    previous = next;
  }
  gl_FragData[0] = vec4(radiance, 1.0);
  gl_FragData[1] = vec4(transmittance, 1.0);
}
