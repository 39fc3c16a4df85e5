// Stage 4's scene depth and normals (cluster_score.comp, scene_normals.comp): the GLSL twin
// of sceneNormal in src/hypotheses/cluster_score_math.hpp, the same operations in the same
// order. Expects the `depth` texel buffer (r32ui: float metres, row-major) and `pc`
// (ScorePush) declared.
float sceneDepth(int x, int y) {
  if (x < 0 || y < 0 || x >= pc.width || y >= pc.height) return 0.0;
  return uintBitsToFloat(texelFetch(depth, y * pc.width + x).x);
}

vec3 backProject(int u, int v, float d) {
  return vec3((float(u) - pc.camera.cx) * (1.0 / pc.camera.fx) * d, (float(v) - pc.camera.cy) * (1.0 / pc.camera.fy) * d,
              d);
}

bool sceneNormal(int x, int y, out vec3 n) {
  int s = pc.normal_step;
  float z = sceneDepth(x, y);
  float zl = sceneDepth(x - s, y), zr = sceneDepth(x + s, y);
  float zu = sceneDepth(x, y - s), zd = sceneDepth(x, y + s);
  n = vec3(0.0);
  if (z <= 0.0 || zl <= 0.0 || zr <= 0.0 || zu <= 0.0 || zd <= 0.0) return false;
  if (abs(zl - z) > pc.max_jump || abs(zr - z) > pc.max_jump || abs(zu - z) > pc.max_jump ||
      abs(zd - z) > pc.max_jump)
    return false;
  precise vec3 dx = backProject(x + s, y, zr) - backProject(x - s, y, zl);
  precise vec3 dy = backProject(x, y + s, zd) - backProject(x, y - s, zu);
  precise vec3 c = cross(dx, dy);
  precise float len = sqrt(dot(c, c));
  if (!(len > 0.0)) return false;
  c = c / len;
  if (dot(c, backProject(x, y, z)) > 0.0) c = -c;
  n = c;
  return true;
}
