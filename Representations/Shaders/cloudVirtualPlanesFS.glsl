// One virtual plane of 002 §6.2: a plane parallel to the screen at view depth
// planeDepth, on which the lights' single scattering by the air is evaluated per pixel
// with their light maps and shadow maps (nimbusLights.glsl) and the air's view
// transmittance, times the planes' spacing. The planes are drawn back to front into
// their own target with S = C + alpha S_before (the cloud's transmittance across the
// plane's slab as alpha), so the cloud hides the beams behind it; the composite adds
// the target to the picture. The paper evaluates the light at the planes' lattice
// points and maps the light map and a shadow texture onto each plane; here every pixel
// of the plane is evaluated, with the same textures.
in vec2 texCoord;
uniform float planeDepth;   // distance of the plane from the eye along viewForward (world)
uniform float planeSpacing; // distance to the next plane (world)
uniform float lightsMieG;

// The shafts' view transmittance of nimbusLights.glsl (unused by the planes, which
// apply AtmosphereViewTransmittance themselves; defined for the library's prototype).
vec3 LightsViewTransmittance(vec3 origin, vec3 direction, float t)
{
  return AtmosphereViewTransmittance(origin, direction, t);
}

void main()
{
  vec3 origin, direction;
  ViewRay(texCoord, origin, direction);
  float tGround;
  float tEnd = RayEnd(texCoord, origin, direction, tGround);
  float along = max(dot(direction, viewForward), 1e-6);
  float t = (planeDepth - dot(origin - cameraPosition, viewForward)) / along;
  if (t < 0.0 || t > tEnd)
  {
    gl_FragData[0] = vec4(0.0, 0.0, 0.0, 1.0);
    return;
  }
  float dt = planeSpacing / along * metresPerUnit;
  vec3 p = origin + t * direction;
  vec3 source = vec3(0.0);
  for (int i = 0; i < lightCount; ++i)
  {
    source += LightScattering(i, p, direction, 0.0, lightsMieG);
  }
  float sigma = extinctionPerDensity * CloudDensity(p);
  gl_FragData[0] =
    vec4(source * AtmosphereViewTransmittance(origin, direction, t) * dt, exp(-sigma * dt));
}
