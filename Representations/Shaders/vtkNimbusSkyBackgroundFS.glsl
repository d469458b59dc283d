//VTK::System::Dec
// Sky background (vtkNimbusSkyBackground): the sky-view table along each pixel's
// view ray, drawn at the far plane (depth 1) where nothing opaque was drawn.
// The framebuffer receives display values: sRGB-encoded displayScale x L.
in vec2 texCoord;
//VTK::Output::Dec

//NIMBUS::Library
//NIMBUS::SkyView

uniform mat4 inverseViewProjection; // VTK matrix (row-major): use as vec4 * M
uniform vec3 cameraPosition;        // scene units

void main()
{
  vec4 far = vec4(texCoord * 2.0 - 1.0, 1.0, 1.0) * inverseViewProjection;
  vec4 near = vec4(texCoord * 2.0 - 1.0, -1.0, 1.0) * inverseViewProjection;
  // Perspective: from the eye; parallel: along the (constant) view direction.
  vec3 w = normalize(far.xyz / far.w - near.xyz / near.w);
  gl_FragData[0] = vec4(SrgbEncode(SkyRadiance(w) * displayScale), 1.0);
  gl_FragDepth = 1.0;
}
