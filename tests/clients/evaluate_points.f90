! Test driver: the Fortran module's view of evaluate_points.c. Reads the number of points, then
! "p[Pa] v[m/s] T[K]" per line from stdin, evaluates them in one block with std and a 95 % interval,
! prints "mu std lo hi status" per point in full precision. Usage: URI < points
program evaluate_points
  use, intrinsic :: iso_c_binding
  use mufric
  implicit none
  real(c_double), allocatable, target :: p(:), v(:), t(:), mu(:), sd(:), lo(:), hi(:)
  integer(c_int), allocatable, target :: status(:)
  type(c_ptr) :: client
  character(len=1024) :: uri
  integer :: k, n

  call get_command_argument(1, uri)
  read (*, *) n
  allocate (p(n), v(n), t(n), mu(n), sd(n), lo(n), hi(n), status(n))
  do k = 1, n
    read (*, *) p(k), v(k), t(k)
  end do
  if (mufric_connect(uri, client) /= MUFRIC_OK) then
    write (0, *) 'mufric_connect: ', mufric_error()
    stop 1
  end if
  if (c_mufric_evaluate(client, int(n, c_size_t), c_loc(p), c_loc(v), c_loc(t), c_null_ptr, 0.95d0, &
                        c_loc(mu), c_loc(sd), c_loc(lo), c_loc(hi), c_loc(status)) == MUFRIC_FAILED) then
    write (0, *) 'mufric_evaluate: ', mufric_error()
    stop 1
  end if
  do k = 1, n
    print '(4es26.17e3, i3)', mu(k), sd(k), lo(k), hi(k), status(k)
  end do
  call c_mufric_close(client)
end program
