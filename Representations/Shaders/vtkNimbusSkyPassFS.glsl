//VTK::System::Dec
// Sky background and aerial perspective (vtkNimbusSkyPass; CPU twin:
// nimbus::SkyViewLut::Radiance and nimbus::AerialPerspectiveLut::Lookup in
// Physics/Sky.cxx — same row/column/slice maps, same phase functions).
//
// Surfaces: colour_out = colour_in * T + DisplayScale * L_inscatter (aerial perspective).
in vec2 texCoord;
//VTK::Output::Dec

//NIMBUS::Library
//NIMBUS::SkyView

uniform sampler2D colorTexture;
uniform sampler2D depthTexture;
uniform sampler3D aerialRayleigh;
uniform sampler3D aerialMie;
uniform sampler3D aerialIsotropic;
uniform sampler3D aerialTransmittance;

uniform mat4 inverseViewProjection; // VTK matrix (row-major): use as vec4 * M
uniform vec3 cameraPosition;        // scene units
uniform float metresPerUnit;

uniform vec4 aerialTable; // horizon zenith (rad), width, rows above, rows below
uniform vec2 aerialSlices; // number of slices, max distance (m)
uniform int aerialPerspective;

vec3 unproject(float ndcZ)
{
  vec4 p = vec4(texCoord * 2.0 - 1.0, ndcZ, 1.0) * inverseViewProjection;
  return p.xyz / p.w;
}

void main()
{
  vec4 color = texture(colorTexture, texCoord);
  float depth = texture(depthTexture, texCoord).r;
  gl_FragDepth = depth;
  if (depth >= 1.0)
  {
    vec3 L = SkyRadiance(normalize(unproject(1.0) - cameraPosition));
    // Translucent props drawn here (no depth) are composited over the sky
    // (premultiplied colour, coverage in alpha).
    gl_FragData[0] = vec4(SrgbEncode(SrgbDecode(color.rgb) + (1.0 - color.a) * L * displayScale), 1.0);
    return;
  }
  if (aerialPerspective == 0)
  {
    gl_FragData[0] = color;
    return;
  }
  vec3 d = unproject(depth * 2.0 - 1.0) - cameraPosition;
  float len = length(d);
  if (!(len > 0.0))
  {
    gl_FragData[0] = color;
    return;
  }
  vec3 w = d / len;
  float distance = len * metresPerUnit;
  vec2 uv = SkyViewUv(w, aerialTable);
  // Slices at D (k/(S-1))^2, linear in the distance between two slices (as the CPU twin).
  float S = aerialSlices.x, D = aerialSlices.y;
  float u = sqrt(clamp(distance / D, 0.0, 1.0)) * (S - 1.0);
  float k0 = min(floor(u), S - 2.0);
  float d0 = D * (k0 / (S - 1.0)) * (k0 / (S - 1.0));
  float d1 = D * ((k0 + 1.0) / (S - 1.0)) * ((k0 + 1.0) / (S - 1.0));
  float fk = clamp((min(distance, D) - d0) / (d1 - d0), 0.0, 1.0);
  vec3 uvw = vec3(uv, (k0 + fk + 0.5) / S);
  float nu = dot(w, sunDirection);
  vec3 inscatter = Rayleigh(nu) * texture(aerialRayleigh, uvw).rgb +
    CornetteShanks(nu, mieG) * texture(aerialMie, uvw).rgb + texture(aerialIsotropic, uvw).rgb;
  vec3 T = texture(aerialTransmittance, uvw).rgb;
  vec3 surface = SrgbDecode(color.rgb);
  gl_FragData[0] = vec4(SrgbEncode(surface * T + inscatter * displayScale), color.a);
}
