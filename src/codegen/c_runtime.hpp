// Private to c_codegen.cpp: the C text of the numerical kernels every
// generated module may need, with "PFX_" standing for the module's prefix
// and an underscore. Each kernel evaluates its sums in the order of the
// Eigen 3.4 kernel the library runs (SSE2, two doubles per packet), cited
// per function; the QP is QpSolver::Solve() of qp_solver.cpp.
#pragma once

namespace pneumid::internal {

// Inner product a'b of n entries as Eigen's vectorized redux
// (Core/Redux.h, LinearVectorizedTraversal): two packets of two lanes, the
// packets added, the lanes added, the odd tail last.
inline constexpr const char kCDot[] = R"C(
static PFX_real PFX_dot(const PFX_real* a, const PFX_real* b, int n) {
  PFX_real s0, s1, res;
  int i, end2, end;
  if (n < 2) return n == 1 ? a[0] * b[0] : PFX_ZERO;
  end2 = (n / 4) * 4;
  end = (n / 2) * 2;
  s0 = a[0] * b[0];
  s1 = a[1] * b[1];
  if (n >= 4) {
    PFX_real t0 = a[2] * b[2], t1 = a[3] * b[3];
    for (i = 4; i < end2; i += 4) {
      s0 += a[i] * b[i];
      s1 += a[i + 1] * b[i + 1];
      t0 += a[i + 2] * b[i + 2];
      t1 += a[i + 3] * b[i + 3];
    }
    s0 += t0;
    s1 += t1;
    if (end > end2) {
      s0 += a[end2] * b[end2];
      s1 += a[end2 + 1] * b[end2 + 1];
    }
  }
  res = s0 + s1;
  for (i = end; i < n; ++i) res += a[i] * b[i];
  return res;
}
)C";

// Sequential inner product of a strided row (a[0], a[stride], ...) with b,
// as Eigen's scalar redux of a row of a column-major matrix.
inline constexpr const char kCDotStrided[] = R"C(
static PFX_real PFX_dot_strided(const PFX_real* a, int stride, const PFX_real* b, int n) {
  PFX_real res;
  int i;
  if (n < 1) return PFX_ZERO;
  res = a[0] * b[0];
  for (i = 1; i < n; ++i) res += a[i * stride] * b[i];
  return res;
}
)C";

// y = (accumulate ? y : 0) + alpha A x, A rows x cols column-major with
// leading dimension lda, as Eigen's general_matrix_vector_product<ColMajor>
// (Core/products/GeneralMatrixVector.h): per row a sequential sum over a
// block of columns (all of them below 128, else blocks of 16), added to y
// times alpha (+-1). (The inner-product fallback of ProductEvaluators.h for
// one row sums sequentially as well.)
inline constexpr const char kCGemvCol[] = R"C(
static void PFX_gemv_col(const PFX_real* A, int lda, int rows, int cols, const PFX_real* x,
                         PFX_real* y, int accumulate, PFX_real alpha) {
  int i, j, j2, jend, block;
  if (!accumulate)
    for (i = 0; i < rows; ++i) y[i] = PFX_ZERO;
  block = cols < 128 ? cols : (lda * (int)sizeof(double) < 32000 ? 16 : 4);
  for (j2 = 0; j2 < cols; j2 += block) {
    jend = j2 + block < cols ? j2 + block : cols;
    for (i = 0; i < rows; ++i) {
      PFX_real c = PFX_ZERO;
      for (j = j2; j < jend; ++j) c += A[i + j * lda] * x[j];
      y[i] += alpha * c;
    }
  }
}
)C";

// y += alpha A x with A rows x cols row-major (the transpose of a
// column-major matrix with leading dimension lda), as
// general_matrix_vector_product<RowMajor>: per row two lanes over pairs of
// columns, the lanes added, the odd column last. (Used for n x n with n >= 2,
// or n = 1 where every order gives the single product.)
inline constexpr const char kCGemvRow[] = R"C(
static void PFX_gemv_row(const PFX_real* A, int lda, int rows, int cols, const PFX_real* x,
                         PFX_real* y, PFX_real alpha) {
  int i, j;
  for (i = 0; i < rows; ++i) {
    const PFX_real* a = A + i * lda;
    PFX_real l0 = PFX_ZERO, l1 = PFX_ZERO, c;
    for (j = 0; j + 2 <= cols; j += 2) {
      l0 += a[j] * x[j];
      l1 += a[j + 1] * x[j + 1];
    }
    c = l0 + l1;
    for (; j < cols; ++j) c += a[j] * x[j];
    y[i] += alpha * c;
  }
}
)C";

// Triangular solves of the QP, as Eigen's triangular_solve_vector
// (Core/products/TriangularSolverVector.h, panels of 8): R x = b with R
// upper, column-major (lda); L x = b and L' x = b with L lower, column-major.
inline constexpr const char kCTriangular[] = R"C(
static void PFX_solve_upper_col(const PFX_real* R, int lda, int size, PFX_real* b) {
  int pi, k, i, r, s, j, width, start;
  for (pi = size; pi > 0; pi -= 8) {
    width = pi < 8 ? pi : 8;
    start = pi - width;
    for (k = 0; k < width; ++k) {
      i = pi - k - 1;
      if (b[i] != PFX_ZERO) {
        b[i] /= R[i + i * lda];
        r = width - k - 1;
        s = i - r;
        for (j = 0; j < r; ++j) b[s + j] -= b[i] * R[s + j + i * lda];
      }
    }
    if (start > 0) PFX_gemv_col(R + start * lda, lda, start, width, b + start, b, 1, -PFX_ONE);
  }
}

static void PFX_solve_lower_col(const PFX_real* L, int lda, int size, PFX_real* b) {
  int pi, k, i, r, j, width, end;
  for (pi = 0; pi < size; pi += 8) {
    width = size - pi < 8 ? size - pi : 8;
    end = pi + width;
    for (k = 0; k < width; ++k) {
      i = pi + k;
      if (b[i] != PFX_ZERO) {
        b[i] /= L[i + i * lda];
        r = width - k - 1;
        for (j = 0; j < r; ++j) b[i + 1 + j] -= b[i] * L[i + 1 + j + i * lda];
      }
    }
    if (size - end > 0)
      PFX_gemv_col(L + end + pi * lda, lda, size - end, width, b + pi, b + end, 1, -PFX_ONE);
  }
}

/* L' x = b: L' is upper and row-major in L's storage (row i of L' = column i of L). */
static void PFX_solve_lower_transpose(const PFX_real* L, int lda, int size, PFX_real* b) {
  int pi, k, i, s, width, start;
  for (pi = size; pi > 0; pi -= 8) {
    width = pi < 8 ? pi : 8;
    start = pi - width;
    if (size - pi > 0) PFX_gemv_row(L + pi + start * lda, lda, width, size - pi, b + pi, b + start, -PFX_ONE);
    for (k = 0; k < width; ++k) {
      i = pi - k - 1;
      s = i + 1;
      if (k > 0) b[i] -= PFX_dot(L + s + i * lda, b + s, k);
      if (b[i] != PFX_ZERO) b[i] /= L[i + i * lda];
    }
  }
}
)C";

// The dual active-set QP of qp_solver.cpp with the sizes, the constraint
// matrix C (m x n, column-major), L (H = L L'), J0 = L^-T, the row norms,
// the simple bounds lbx/ubx and the iteration cap as constants, and the
// per-solve data and work arrays in the caller's state (PFX_qp). Constraint
// k < 2m is side k%2 of row k/2 of C (normal -C_i for the upper side), k >=
// 2m side k%2 of bound (k-2m)/2.
inline constexpr const char kCQp[] = R"C(
static PFX_real PFX_qp_row_norm(int k) {
  return k < 2 * PFX_QP_M ? PFX_qp_norm[k / 2] : PFX_ONE;
}

static PFX_real PFX_qp_rhs(const PFX_qp* w, int k) {
  int j;
  if (k < 2 * PFX_QP_M) return (k % 2) ? -w->ub[k / 2] : w->lb[k / 2];
  j = (k - 2 * PFX_QP_M) / 2;
  return (k % 2) ? -PFX_qp_ubx[j] : PFX_qp_lbx[j];
}

static int PFX_qp_is_equality(const PFX_qp* w, int k) {
  int j;
  if (k % 2) return 0;
  if (k < 2 * PFX_QP_M) return w->lb[k / 2] == w->ub[k / 2];
  j = (k - 2 * PFX_QP_M) / 2;
  return PFX_qp_lbx[j] == PFX_qp_ubx[j];
}

static void PFX_qp_normal(int k, PFX_real* out) {
  int j;
  if (k < 2 * PFX_QP_M) {
    for (j = 0; j < PFX_QP_N; ++j) out[j] = PFX_qp_C[k / 2 + j * PFX_QP_M];
    if (k % 2)
      for (j = 0; j < PFX_QP_N; ++j) out[j] = -out[j];
  } else {
    for (j = 0; j < PFX_QP_N; ++j) out[j] = PFX_ZERO;
    out[(k - 2 * PFX_QP_M) / 2] = (k % 2) ? -PFX_ONE : PFX_ONE;
  }
}

static PFX_real PFX_qp_normal_dot(int k, const PFX_real* v) {
  PFX_real c;
  if (k < 2 * PFX_QP_M) {
    c = PFX_dot_strided(PFX_qp_C + k / 2, PFX_QP_M, v, PFX_QP_N);
    return (k % 2) ? -c : c;
  }
  c = v[(k - 2 * PFX_QP_M) / 2];
  return (k % 2) ? -c : c;
}

static void PFX_qp_add(PFX_qp* w, int k, PFX_real multiplier) {
  int i, row;
  const int n = PFX_QP_N, q = w->q;
  for (i = n - 1; i > q; --i) {
    PFX_real a = w->d[i - 1], b = w->d[i], h, c, s;
    if (b == PFX_ZERO) continue;
    h = PFX_HYPOT(a, b);
    c = a / h;
    s = b / h;
    w->d[i - 1] = h;
    w->d[i] = PFX_ZERO;
    for (row = 0; row < n; ++row) {
      PFX_real j1 = w->J[row + (i - 1) * n], j2 = w->J[row + i * n];
      w->J[row + (i - 1) * n] = c * j1 + s * j2;
      w->J[row + i * n] = -s * j1 + c * j2;
    }
  }
  for (i = 0; i <= q; ++i) w->R[i + q * n] = w->d[i];
  for (i = q + 1; i < n; ++i) w->R[i + q * n] = PFX_ZERO;
  w->active[q] = k;
  w->u[q] = multiplier;
  w->is_active[k] = 1;
  w->q = q + 1;
}

static void PFX_qp_drop(PFX_qp* w, int position) {
  int i, j, col, row;
  const int n = PFX_QP_N;
  w->is_active[w->active[position]] = 0;
  for (j = position; j < w->q - 1; ++j) {
    w->active[j] = w->active[j + 1];
    w->u[j] = w->u[j + 1];
    for (i = 0; i <= j + 1; ++i) w->R[i + j * n] = w->R[i + (j + 1) * n];
  }
  --w->q;
  for (j = position; j < w->q; ++j) {
    PFX_real a = w->R[j + j * n], b = w->R[j + 1 + j * n], h, c, s;
    if (b == PFX_ZERO) continue;
    h = PFX_HYPOT(a, b);
    c = a / h;
    s = b / h;
    for (col = j; col < w->q; ++col) {
      PFX_real r1 = w->R[j + col * n], r2 = w->R[j + 1 + col * n];
      w->R[j + col * n] = c * r1 + s * r2;
      w->R[j + 1 + col * n] = -s * r1 + c * r2;
    }
    w->R[j + 1 + j * n] = PFX_ZERO;
    for (row = 0; row < n; ++row) {
      PFX_real j1 = w->J[row + j * n], j2 = w->J[row + (j + 1) * n];
      w->J[row + j * n] = c * j1 + s * j2;
      w->J[row + (j + 1) * n] = -s * j1 + c * j2;
    }
  }
}

static int PFX_qp_finish(PFX_qp* w, int status) {
  int j;
  w->status = status;
  w->nwarm = 0;
  if (status == PFX_QP_SOLVED) {
    for (j = 0; j < w->q; ++j)
      if (!PFX_qp_is_equality(w, w->active[j])) w->warm[w->nwarm++] = w->active[j];
  }
  return status;
}

/* d = J' n_p, z = J(:, q:) d(q:), r = R(0:q, 0:q)^-1 d(0:q). */
static void PFX_qp_directions(PFX_qp* w) {
  const int n = PFX_QP_N, q = w->q;
  int i;
  for (i = 0; i < n; ++i) w->d[i] = PFX_ZERO;
  PFX_gemv_row(w->J, n, n, n, w->np, w->d, PFX_ONE);
  PFX_gemv_col(w->J + q * n, n, n, n - q, w->d + q, w->z, 0, PFX_ONE);
  for (i = 0; i < q; ++i) w->r[i] = w->d[i];
  PFX_solve_upper_col(w->R, n, q, w->r);
}

/* minimize 1/2 x'Hx + g'x subject to lb <= C x <= ub, lbx <= x <= ubx,
   with g, lb, ub in w; returns the status (PFX_QP_SOLVED, ...). */
static int PFX_qp_solve(PFX_qp* w) {
  const int n = PFX_QP_N, num_constraints = 2 * (PFX_QP_M + PFX_QP_N);
  const PFX_real tol = PFX_QP_TOLERANCE, eps = PFX_EPSILON;
  int k, j, finite_sides = 0, max_iter, warm_next = 0;
  w->iterations = 0;
  for (k = 0; k < num_constraints; ++k) finite_sides += PFX_ISFINITE(PFX_qp_rhs(w, k)) ? 1 : 0;
  max_iter = PFX_QP_MAX_ITERATIONS > 0 ? PFX_QP_MAX_ITERATIONS : 10 * (n + finite_sides) + 10;

  memcpy(w->J, PFX_qp_J0, sizeof(w->J));
  w->q = 0;
  memset(w->is_active, 0, sizeof(w->is_active));
  for (j = 0; j < n; ++j) w->x[j] = -w->g[j];
  PFX_solve_lower_col(PFX_qp_L, n, n, w->x);
  PFX_solve_lower_transpose(PFX_qp_L, n, n, w->x);

  for (k = 0; k < num_constraints; k += 2) {
    PFX_real s, zn, t;
    if (!PFX_qp_is_equality(w, k) || !PFX_ISFINITE(PFX_qp_rhs(w, k))) continue;
    PFX_qp_normal(k, w->np);
    PFX_qp_directions(w);
    s = PFX_qp_normal_dot(k, w->x) - PFX_qp_rhs(w, k);
    zn = PFX_dot(w->z, w->np, n);
    if (PFX_FABS(zn) <= PFX_THOUSAND * eps * PFX_dot(w->np, w->np, n) || w->q == n) {
      if (PFX_FABS(s) > tol * PFX_qp_row_norm(k)) return PFX_qp_finish(w, PFX_QP_INFEASIBLE);
      continue;
    }
    t = -s / zn;
    for (j = 0; j < n; ++j) w->x[j] += t * w->z[j];
    for (j = 0; j < w->q; ++j) w->u[j] -= t * w->r[j];
    PFX_qp_add(w, k, t);
    ++w->iterations;
  }

  for (;;) {
    int p = -1;
    PFX_real u_plus = PFX_ZERO;
    if (PFX_QP_WARM_START) {
      while (warm_next < w->nwarm && p < 0) {
        k = w->warm[warm_next++];
        if (w->is_active[k] || !PFX_ISFINITE(PFX_qp_rhs(w, k))) continue;
        if ((PFX_qp_normal_dot(k, w->x) - PFX_qp_rhs(w, k)) / PFX_qp_row_norm(k) < -tol) p = k;
      }
    }
    if (p < 0) {
      PFX_real worst = -tol;
      PFX_gemv_col(PFX_qp_C, PFX_QP_M, PFX_QP_M, n, w->x, w->cx, 0, PFX_ONE);
      for (k = 0; k < num_constraints; ++k) {
        PFX_real b, v, s;
        if (w->is_active[k]) continue;
        b = PFX_qp_rhs(w, k);
        if (!PFX_ISFINITE(b)) continue;
        if (k % 2 == 1 && PFX_qp_is_equality(w, k - 1)) continue;
        if (k < 2 * PFX_QP_M)
          v = (k % 2) ? -w->cx[k / 2] : w->cx[k / 2];
        else
          v = (k % 2) ? -w->x[(k - 2 * PFX_QP_M) / 2] : w->x[(k - 2 * PFX_QP_M) / 2];
        s = (v - b) / PFX_qp_row_norm(k);
        if (s < worst) {
          worst = s;
          p = k;
        }
      }
    }
    if (p < 0) return PFX_qp_finish(w, PFX_QP_SOLVED);

    PFX_qp_normal(p, w->np);
    for (;;) {
      PFX_real t1 = PFX_INF, t2 = PFX_INF, zn, s, t;
      int drop = -1;
      if (w->iterations >= max_iter) return PFX_qp_finish(w, PFX_QP_MAX_ITERATIONS_REACHED);
      PFX_qp_directions(w);
      for (j = 0; j < w->q; ++j) {
        if (PFX_qp_is_equality(w, w->active[j])) continue;
        if (w->r[j] > PFX_ZERO) {
          const PFX_real ratio = w->u[j] / w->r[j];
          if (ratio < t1) {
            t1 = ratio;
            drop = j;
          }
        }
      }
      zn = PFX_dot(w->z, w->np, n);
      s = PFX_qp_normal_dot(p, w->x) - PFX_qp_rhs(w, p);
      if (w->q < n && PFX_FABS(zn) > PFX_THOUSAND * eps * PFX_dot(w->np, w->np, n)) t2 = -s / zn;
      if (t2 < PFX_ZERO) t2 = PFX_ZERO;
      if (!PFX_ISFINITE(t1) && !PFX_ISFINITE(t2)) return PFX_qp_finish(w, PFX_QP_INFEASIBLE);
      if (!PFX_ISFINITE(t2)) {
        for (j = 0; j < w->q; ++j) w->u[j] -= t1 * w->r[j];
        u_plus += t1;
        PFX_qp_drop(w, drop);
        ++w->iterations;
        continue;
      }
      t = t1 < t2 ? t1 : t2;
      for (j = 0; j < n; ++j) w->x[j] += t * w->z[j];
      for (j = 0; j < w->q; ++j) w->u[j] -= t * w->r[j];
      u_plus += t;
      ++w->iterations;
      if (t2 <= t1) {
        PFX_qp_add(w, p, u_plus);
        break;
      }
      PFX_qp_drop(w, drop);
    }
  }
}
)C";

}  // namespace pneumid::internal
