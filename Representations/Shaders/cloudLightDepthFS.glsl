// One z-slice of a view light's transmittance volume (nimbusLights.glsl,
// LightCloudTransmittance): at each texel's centre, the cloud's transmittance
// exp(-tau) toward the light, tau the integral of k rho along the segment's part inside
// the density box (cloudSteps midpoint samples). Stored as the transmittance, so the
// texture's trilinear filter averages light, as the sun-depth volume does
// (SunDepthVolume.h). Drawn when the density, the light or the optics change.
in vec2 texCoord;
uniform mat4 boxToWorld;     // [0,1]^3 over the density's box -> world (up frame)
uniform float sliceW;        // this slice's box coordinate along the third axis
uniform vec3 sourcePosition; // the light (world)
uniform int cloudSteps;

void main()
{
  vec3 p = (boxToWorld * vec4(texCoord, sliceW, 1.0)).xyz;
  vec3 d = sourcePosition - p;
  float tIn, tOut;
  float tau = 0.0;
  if (BoxInterval(p, d, tIn, tOut))
  {
    tIn = max(tIn, 0.0);
    tOut = min(tOut, 1.0);
    if (tOut > tIn)
    {
      float dt = (tOut - tIn) / float(cloudSteps);
      float sum = 0.0;
      for (int k = 0; k < cloudSteps; ++k)
      {
        sum += CloudDensity(p + (tIn + (float(k) + 0.5) * dt) * d);
      }
      tau = extinctionPerDensity * sum * dt * length(d) * metresPerUnit;
    }
  }
  gl_FragData[0] = vec4(exp(-tau), 0.0, 0.0, 1.0);
}
