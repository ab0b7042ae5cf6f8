/* quantities.c: the reader's checked physical quantities: an inertia
 * (principal, full or as a matrix; symmetric positive definite, triangle
 * inequalities) and an orientation (Euler parameters or axis and angle). */
#include "quantities.h"

#include <math.h>
#include <stdio.h>
#include <string.h>

/* Eigenvalues of a symmetric 3x3 matrix by cyclic Jacobi rotations. */
static void symmetric_eigenvalues(const double matrix[9], double eigenvalues[3]) {
  double a[3][3];
  for (int i = 0; i < 3; i++)
    for (int j = 0; j < 3; j++)
      a[i][j] = matrix[3 * i + j];
  for (int sweep = 0; sweep < 50; sweep++) {
    double off = a[0][1] * a[0][1] + a[0][2] * a[0][2] + a[1][2] * a[1][2];
    double diagonal = a[0][0] * a[0][0] + a[1][1] * a[1][1] + a[2][2] * a[2][2];
    if (!(off > 1e-32 * diagonal))
      break;
    for (int p = 0; p < 2; p++) {
      for (int q = p + 1; q < 3; q++) {
        if (a[p][q] == 0)
          continue;
        double theta = (a[q][q] - a[p][p]) / (2 * a[p][q]);
        double t = fabs(theta) > 1e150 ? 0.5 / theta
                                       : (theta >= 0 ? 1 : -1) / (fabs(theta) + sqrt(theta * theta + 1));
        double c = 1 / sqrt(t * t + 1), s = t * c;
        for (int k = 0; k < 3; k++) { /* a := a P, then P^T a */
          double akp = a[k][p], akq = a[k][q];
          a[k][p] = c * akp - s * akq;
          a[k][q] = s * akp + c * akq;
        }
        for (int k = 0; k < 3; k++) {
          double apk = a[p][k], aqk = a[q][k];
          a[p][k] = c * apk - s * aqk;
          a[q][k] = s * apk + c * aqk;
        }
      }
    }
  }
  for (int i = 0; i < 3; i++)
    eigenvalues[i] = a[i][i];
}

static bool cholesky_succeeds(const double a[9]) {
  double l[3][3] = {{0}};
  for (int j = 0; j < 3; j++) {
    double d = a[3 * j + j];
    for (int k = 0; k < j; k++)
      d -= l[j][k] * l[j][k];
    if (!(d > 0))
      return false;
    l[j][j] = sqrt(d);
    for (int i = j + 1; i < 3; i++) {
      double v = a[3 * i + j];
      for (int k = 0; k < j; k++)
        v -= l[i][k] * l[j][k];
      l[i][j] = v / l[j][j];
    }
  }
  return true;
}

/* [Ixx, Iyy, Izz], [Ixx, Iyy, Izz, Ixy, Ixz, Iyz] or a 3x3 matrix; must be
 * symmetric positive definite with physically possible principal moments. */
bool parse_inertia(reader *r, yaml_node_t *n, double inertia[9]) {
  double I[9] = {0};
  int length = n->type == YAML_SEQUENCE_NODE ? seq_length(n) : -1;
  bool matrix = length == 3 && seq_item(r, n, 0)->type == YAML_SEQUENCE_NODE;
  if (matrix) {
    if (!to_vector_list(r, n, "'inertia'", 3, 3, I))
      return false;
    double largest = 0;
    for (int i = 0; i < 9; i++)
      largest = fmax(largest, fabs(I[i]));
    for (int i = 0; i < 3; i++) {
      for (int j = i + 1; j < 3; j++) {
        if (fabs(I[3 * i + j] - I[3 * j + i]) > 1e-9 * largest) {
          error_at(r, loc_of(n),
                   "'inertia' must be symmetric (row %d column %d is %g but row %d column %d "
                   "is %g)",
                   i + 1, j + 1, I[3 * i + j], j + 1, i + 1, I[3 * j + i]);
          return false;
        }
        I[3 * i + j] = I[3 * j + i] = 0.5 * (I[3 * i + j] + I[3 * j + i]);
      }
    }
  } else if (length == 3 || length == 6) {
    double v[6] = {0};
    if (!to_vector(r, n, "'inertia'", length, v))
      return false;
    I[0] = v[0];
    I[4] = v[1];
    I[8] = v[2];
    I[1] = I[3] = v[3]; /* Ixy */
    I[2] = I[6] = v[4]; /* Ixz */
    I[5] = I[7] = v[5]; /* Iyz */
  } else {
    char got[SHOWN_SIZE];
    if (length >= 0)
      snprintf(got, sizeof got, "a list of %d", length);
    else
      snprintf(got, sizeof got, "%s", show_node(r, n));
    error_at(r, loc_of(n),
             "'inertia': expected [Ixx, Iyy, Izz], [Ixx, Iyy, Izz, Ixy, Ixz, Iyz] or a 3x3 "
             "matrix, got %s",
             got);
    return false;
  }

  double moments[3];
  symmetric_eigenvalues(I, moments);
  if (!cholesky_succeeds(I)) {
    error_at(r, loc_of(n),
             "'inertia' is not positive definite (principal moments %g, %g, %g; all must be > 0)",
             moments[0], moments[1], moments[2]);
    return false;
  }
  double sum = moments[0] + moments[1] + moments[2];
  for (int i = 0; i < 3; i++) {
    double others = sum - moments[i];
    if (moments[i] > others + 1e-9 * sum) {
      error_at(r, loc_of(n),
               "'inertia' violates the triangle inequality: principal moment %g exceeds the "
               "sum of the other two (%g)",
               moments[i], others);
      return false;
    }
  }
  memcpy(inertia, I, sizeof I);
  return true;
}

/* Euler parameters [e0, e1, e2, e3] (normalized here) or {axis, angle}. */
void parse_orientation(reader *r, yaml_node_t *n, const char *owner, double e[4]) {
  if (n->type == YAML_SEQUENCE_NODE) {
    double v[4];
    if (!to_vector(r, n, "'orientation'", 4, v))
      return;
    double length = safe_norm(v, 4);
    if (!(length >= ZERO_LENGTH)) {
      error_at(r, loc_of(n), "'orientation': the Euler parameters have zero length");
      return;
    }
    for (int i = 0; i < 4; i++)
      e[i] = v[i] / length;
  } else if (n->type == YAML_MAPPING_NODE) {
    mapping m;
    map_open(&m, r, n, loc_of(n), "'orientation' of %s", owner);
    static const char *const keys[] = {"axis", "angle", NULL};
    map_check_keys(&m, keys);
    double axis[3], angle;
    bool ok = get_axis(&m, "axis", true, axis);
    ok = get_number(&m, "angle", true, &angle) && ok;
    if (ok) {
      e[0] = cos(0.5 * angle);
      for (int i = 0; i < 3; i++)
        e[i + 1] = axis[i] * sin(0.5 * angle);
    }
    map_close(&m);
  } else {
    error_at(r, loc_of(n),
             "'orientation': expected Euler parameters [e0, e1, e2, e3] or {axis: [x, y, z], "
             "angle: radians}, got %s",
             show_node(r, n));
  }
}
